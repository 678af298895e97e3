"""The BARN suites' speed line: CPU per run per navigator and the 300-world projection (figures, not asserted)."""

from swarmnav.benchmarks.navigation_speed import speed_lines


def test_barn_rows_get_a_cpu_per_run_line_with_the_300_world_projection():
    rows = [{"navigator": "dwa", "realtime_factor": 5.0, "realtime_factor_cpu": 6.0, "barn_score": 0.4,
             "cpu_s_per_run": 4.0},
            {"navigator": "velocity_obstacle", "realtime_factor": 9.0, "realtime_factor_cpu": 12.0, "barn_score": 0.4,
             "cpu_s_per_run": 2.0}]
    line = next(line for line in speed_lines(rows, {}, None) if line.startswith("CPU per run: "))
    assert line.startswith("CPU per run: dwa 4.00 s, velocity_obstacle 2.00 s (BARN's 300 worlds x 1 run at these "
                           "means: 30.0 CPU-min, 15.0 min on 2 cores; load average ")


def test_other_suites_have_no_barn_line():
    rows = [{"navigator": "dwa", "realtime_factor": 5.0, "realtime_factor_cpu": 6.0, "cpu_s_per_run": 4.0}]
    assert not any(line.startswith("CPU per run") for line in speed_lines(rows, {}, None))
