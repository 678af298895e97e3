/* The compiled colony walk: planners/ant_colony.py walk_colony_reference, one ant at a time, in C.
 *
 * walk_block(cell_weights, turn_weights, table, step_lengths_9, uniforms, first_step, end_step, n,
 *            goal, width, backtrack, max_length, keys, unvisited, walking, key, run, walked,
 *            steps, length, reached) -> ants still walking
 *
 * Arrays are C-contiguous NumPy buffers (float64, int64, bool), checked for size here.  The
 * arithmetic is the reference's, operation for operation and in the same order (the product of
 * the turn and cell weights, times the tabu mask, a running sum, the roulette count, the tour
 * length's additions), so the tours are the same bit for bit; it is built with
 * -ffp-contract=off so that no multiply-add is fused.  See planners/ant_colony.py walk_colony for
 * the caller (which draws the uniforms) and tests/test_colony_kernel.py for the comparison.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>
#include <string.h>

static int check(Py_buffer *b, Py_ssize_t count, Py_ssize_t itemsize, const char *name) {
    if (b->len != count * itemsize) {
        PyErr_Format(PyExc_ValueError, "walk_block: %s has %zd bytes, expected %zd", name, b->len,
                     count * itemsize);
        return 0;
    }
    return 1;
}

static PyObject *walk_block(PyObject *self, PyObject *args) {
    Py_buffer b_cell, b_turn, b_table, b_lengths, b_uniforms;
    Py_buffer b_keys, b_unvisited, b_walking, b_key, b_run, b_walked, b_steps, b_length, b_reached;
    Py_ssize_t first_step, end_step, n, goal, width, block;
    int backtrack;
    double max_length;
    if (!PyArg_ParseTuple(args, "y*y*y*y*y*nnnnnnpdw*w*w*w*w*w*w*w*w*", &b_cell, &b_turn, &b_table,
                          &b_lengths, &b_uniforms, &block, &first_step, &end_step, &n, &goal, &width,
                          &backtrack, &max_length, &b_keys, &b_unvisited, &b_walking, &b_key, &b_run,
                          &b_walked, &b_steps, &b_length, &b_reached))
        return NULL;
    Py_buffer *all[] = {&b_cell, &b_turn, &b_table, &b_lengths, &b_uniforms, &b_keys, &b_unvisited,
                        &b_walking, &b_key, &b_run, &b_walked, &b_steps, &b_length, &b_reached};
    const Py_ssize_t ants = b_walking.len;
    const Py_ssize_t size = ants * (n + 1);
    const Py_ssize_t turn_rows = b_turn.len / (8 * (Py_ssize_t)sizeof(double));
    PyObject *result = NULL;
    if (!(check(&b_cell, n * 8, sizeof(double), "cell_weights") && (turn_rows == 1 || turn_rows == 9)
          && check(&b_turn, turn_rows * 8, sizeof(double), "turn_weights")
          && check(&b_table, n * 8, sizeof(int64_t), "table")
          && check(&b_lengths, 9, sizeof(double), "step_lengths_9")
          && check(&b_uniforms, block * ants, sizeof(double), "uniforms")
          && check(&b_keys, ants * width, sizeof(int64_t), "keys")
          && check(&b_unvisited, size, 1, "unvisited") && check(&b_key, ants, sizeof(int64_t), "key")
          && check(&b_run, ants, sizeof(int64_t), "run") && check(&b_walked, ants, sizeof(double), "walked")
          && check(&b_steps, ants, sizeof(int64_t), "steps")
          && check(&b_length, ants, sizeof(double), "length") && check(&b_reached, ants, 1, "reached"))) {
        if (!PyErr_Occurred())
            PyErr_SetString(PyExc_ValueError, "walk_block: turn_weights must have 1 or 9 rows of 8");
        goto done;
    }
    if (block < 1 || n < 1 || first_step < 0 || end_step >= width) {
        PyErr_SetString(PyExc_ValueError, "walk_block: needs block >= 1, n >= 1, first_step >= 0 and "
                        "end_step < width (a tour stack holds width keys)");
        goto done;
    }
    const double *cell_weights = b_cell.buf, *turn_weights = b_turn.buf, *step_lengths_9 = b_lengths.buf;
    const double *uniforms = b_uniforms.buf;
    const int64_t *table = b_table.buf;
    int64_t *keys = b_keys.buf, *key = b_key.buf, *run = b_run.buf, *steps = b_steps.buf;
    unsigned char *unvisited = b_unvisited.buf, *walking = b_walking.buf, *reached = b_reached.buf;
    double *walked = b_walked.buf, *length = b_length.buf;
    const int no_turns = turn_rows == 1;
    /* The table's entries are checked where an ant reads them (a cell's 8 moves, each time an ant stands on
     * it), not all n x 8 of them at every call: that scan, once per block of steps, cost about as much as the
     * walk itself on BARN's 140 x 320 cells (3,500 calls a run). */
    Py_ssize_t still = 0, bad_ant = -1, bad_entry = -1;
    for (Py_ssize_t a = 0; a < ants; a++) {
        if (walking[a] && (run[a] < 0 || run[a] > first_step)) {
            PyErr_Format(PyExc_ValueError, "walk_block: ant %zd's stack top %lld is outside 0..%zd", a,
                         (long long)run[a], first_step);
            goto done;
        }
        still += walking[a] != 0;
    }
    Py_BEGIN_ALLOW_THREADS
    double cumulative[8];
    for (Py_ssize_t step = first_step; step < end_step && still > 0; step++) {
        const double *row = uniforms + (step % block) * ants;
        Py_ssize_t j = 0;
        for (Py_ssize_t a = 0; a < ants; a++) {
            if (!walking[a])
                continue;
            const double u = row[j++];
            const int64_t k = key[a];
            if (k < 0 || k >= 9 * n) {   /* a move to no cell: a positive weight on an illegal move */
                bad_ant = a;
                still = 0;
                break;
            }
            const int64_t previous = k / n, cell = k % n;
            const Py_ssize_t base = a * (n + 1);
            const int64_t *moves = table + cell * 8;
            int bad_move = 0;
            for (int d = 0; d < 8; d++)
                bad_move |= moves[d] < -1 || moves[d] >= n;
            if (bad_move) {
                bad_entry = cell * 8;
                still = 0;
                break;
            }
            double total = 0.0;
            for (int d = 0; d < 8; d++) {
                Py_ssize_t slot = base + moves[d];   /* -1 (illegal) reads the previous dummy slot */
                if (slot < 0)
                    slot += size;
                double w = no_turns ? cell_weights[cell * 8 + d]
                                    : turn_weights[previous * 8 + d] * cell_weights[cell * 8 + d];
                w = w * (unvisited[slot] ? 1.0 : 0.0);
                total += w;
                cumulative[d] = total;
            }
            const double draw = u * total;
            int choice = 0;
            for (int d = 0; d < 8; d++)
                choice += cumulative[d] <= draw;
            if (choice > 7)   /* draw == total by rounding */
                choice = 7;
            const int64_t next = moves[choice];
            const int64_t new_key = choice * n + next;
            int arrived = 0, keep;
            if (total > 0.0) {
                walked[a] += step_lengths_9[choice];
                run[a] += 1;
                keys[a * width + run[a]] = new_key;
                Py_ssize_t slot = base + next;
                if (slot < 0)
                    slot += size;
                unvisited[slot] = 0;
                key[a] = new_key;
                arrived = next == goal;
                keep = !arrived && walked[a] <= max_length;
            } else {   /* stuck: step back (the top is overwritten) */
                walked[a] += -step_lengths_9[previous];
                keys[a * width + run[a]] = new_key;
                if (backtrack)
                    run[a] -= 1;
                unvisited[base + n] = 0;
                if (run[a] >= 0)
                    key[a] = keys[a * width + run[a]];
                keep = backtrack && walked[a] <= max_length && run[a] >= 0;
            }
            if (!keep) {
                walking[a] = 0;
                still -= 1;
                steps[a] = run[a] > 0 ? run[a] : 0;
                length[a] = walked[a];
                if (arrived)
                    reached[a] = 1;
            }
        }
    }
    Py_END_ALLOW_THREADS
    if (bad_entry >= 0) {
        for (Py_ssize_t i = bad_entry; i < bad_entry + 8; i++)
            if (table[i] < -1 || table[i] >= n) {
                PyErr_Format(PyExc_ValueError, "walk_block: table[%zd] = %lld is not a cell or -1", i,
                             (long long)table[i]);
                break;
            }
    } else if (bad_ant >= 0)
        PyErr_Format(PyExc_ValueError, "walk_block: ant %zd moved to no cell (cell_weights must be 0 "
                     "where table is -1)", bad_ant);
    else
        result = PyLong_FromSsize_t(still);
done:
    for (size_t i = 0; i < sizeof(all) / sizeof(all[0]); i++)
        PyBuffer_Release(all[i]);
    return result;
}

static PyMethodDef methods[] = {
    {"walk_block", walk_block, METH_VARARGS,
     "Advance the walking ants of a colony by up to one block of steps; return how many still walk."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_colony_walk",
                                   "The compiled colony walk (see planners/ant_colony.py).", -1, methods};

PyMODINIT_FUNC PyInit__colony_walk(void) { return PyModule_Create(&module); }
