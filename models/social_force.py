"""Helbing and Molnár (1995)'s social force model of pedestrians, one explicit step for a group at once.

"Social force model for pedestrian dynamics", Phys. Rev. E 51(5), 4282-4286.  Written from the paper (no
library: see the README's crowd section for why); the equation numbers are the paper's as we recall its layout
(its text was not available here to check them against):

* Eq. (2): the acceleration toward the desired velocity, ``(v0 e - v) / tau``.
* Eqs. (3)-(4): the repulsion of pedestrian beta, ``f = -grad_r V(b)`` with ``V(b) = V0 exp(-b / sigma)`` and
  ``b`` the semi-minor axis of the ellipse through alpha with foci beta and beta's position a step
  ``s = v_beta dt_e e_beta`` ahead: ``2b = sqrt((|r| + |r - s|)^2 - |s|^2)``, ``r = r_alpha - r_beta``.
* Eq. (5): the repulsion of a border (a static disc or box), ``-grad U(|r_aB|)`` with ``U = U0 exp(-|r_aB| / R)``.
* Eq. (7): the weight of what is out of sight, ``w = 1`` if ``e . f >= |f| cos(phi)``, else ``c``.
* Eqs. (9)-(10): ``dw/dt = F + fluctuations``, ``v = w`` capped at ``v_max = 1.3 v0``.

Parameters as the paper gives them: ``tau = 0.5 s``, ``V0 = 2.1 m^2/s^2``, ``sigma = 0.3 m``, ``dt_e = 2 s``,
``U0 = 10 m^2/s^2``, ``R = 0.2 m``, ``2 phi = 200 deg``, ``c = 0.5``.  Our choices where the paper is silent:

* Pedestrians in the paper are points; ours are discs.  Distances in ``V`` and ``U`` are taken between the
  surfaces (``b`` minus the sum of the radii, ``|r_aB|`` minus the agent's radius, both at least 0), so that
  the repulsion is the paper's at the paper's separations of points.
* The attractive effects (the paper's Eq. (6)) are not modelled.
* Fluctuations: a uniform random acceleration of at most ``FLUCTUATION_M_S2`` in a uniform direction, drawn
  from the run's world seed (they break the perfect symmetry of head-on encounters, as the paper intends).
* Integration: explicit Euler at the control period (the paper's Eq. (9) is a differential equation).
"""

from __future__ import annotations

import math

import numpy as np

TAU_S = 0.5
V0_M2_S2 = 2.1
SIGMA_M = 0.3
LOOKAHEAD_S = 2.0
U0_M2_S2 = 10.0
R_M = 0.2
HALF_SIGHT_RAD = math.radians(100.0)
OUT_OF_SIGHT_WEIGHT = 0.5
MAX_SPEED_FACTOR = 1.3
FLUCTUATION_M_S2 = 0.05


def pedestrian_forces(pos_m: np.ndarray, radii_m: np.ndarray, others_m: np.ndarray, other_vel_m_s: np.ndarray,
                      other_radii_m: np.ndarray, self_index: np.ndarray | None = None) -> np.ndarray:
    """(A, 2) sum over the others of Eqs. (3)-(4) on each agent; ``self_index[a]``: agent a's own row among
    the others (excluded), or -1."""
    r = pos_m[:, None, :] - others_m[None, :, :]  # (A, O, 2) r_alpha - r_beta
    speed = np.hypot(other_vel_m_s[:, 0], other_vel_m_s[:, 1])
    heading = np.divide(other_vel_m_s, speed[:, None], out=np.zeros_like(other_vel_m_s), where=speed[:, None] > 0)
    s = (speed * LOOKAHEAD_S)[None, :, None] * heading[None, :, :]  # the step of beta, Eq. (4)
    rs = r - s
    a = np.hypot(r[..., 0], r[..., 1])
    c = np.hypot(rs[..., 0], rs[..., 1])
    s_len = np.hypot(s[..., 0], s[..., 1])
    b = 0.5 * np.sqrt(np.maximum((a + c) ** 2 - s_len ** 2, 1e-12))
    gap = np.maximum(b - (radii_m[:, None] + other_radii_m[None, :]), 0.0)
    # -grad_r V(b) = (V0 / sigma) exp(-b / sigma) grad_r b, grad_r b = (a + c) (r/a + (r - s)/c) / (4 b)
    unit_sum = r / np.maximum(a, 1e-9)[..., None] + rs / np.maximum(c, 1e-9)[..., None]
    magnitude = (V0_M2_S2 / SIGMA_M) * np.exp(-gap / SIGMA_M) * (a + c) / (4.0 * b)
    force = magnitude[..., None] * unit_sum
    if self_index is not None:
        own = self_index >= 0
        force[np.flatnonzero(own), self_index[own]] = 0.0
    return force


def border_forces(pos_m: np.ndarray, radii_m: np.ndarray, discs: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """(A, K, 2) Eq. (5) from every static disc (x, y, r) and box (x_min, y_min, x_max, y_max)."""
    parts = []
    if len(discs):
        d = pos_m[:, None, :] - discs[None, :, :2]
        dist = np.hypot(d[..., 0], d[..., 1])
        normal = d / np.maximum(dist, 1e-9)[..., None]
        parts.append((dist - discs[None, :, 2], normal))
    if len(boxes):
        nearest = np.clip(pos_m[:, None, :], boxes[None, :, :2], boxes[None, :, 2:])
        d = pos_m[:, None, :] - nearest
        dist = np.hypot(d[..., 0], d[..., 1])
        normal = d / np.maximum(dist, 1e-9)[..., None]
        parts.append((dist, normal))
    if not parts:
        return np.zeros((len(pos_m), 0, 2))
    gap = np.concatenate([p[0] for p in parts], axis=1)
    normal = np.concatenate([p[1] for p in parts], axis=1)
    surface = np.maximum(gap - radii_m[:, None], 0.0)
    return ((U0_M2_S2 / R_M) * np.exp(-surface / R_M))[..., None] * normal


def sight_weight(desired_dir: np.ndarray, forces: np.ndarray) -> np.ndarray:
    """Eq. (7): 1 for a force from within the field of view (the force points against the direction of
    motion when its source is ahead), ``c`` otherwise; (A, K)."""
    # The source lies along -f: it is in sight when e . (-f) >= |f| cos(phi).
    along = -np.einsum("ad,akd->ak", desired_dir, forces)
    return np.where(along >= np.hypot(forces[..., 0], forces[..., 1]) * math.cos(HALF_SIGHT_RAD), 1.0,
                    OUT_OF_SIGHT_WEIGHT)


def step(pos_m: np.ndarray, vel_m_s: np.ndarray, radii_m: np.ndarray, pref_vel_m_s: np.ndarray,
         v_pref_m_s: np.ndarray, others_m: np.ndarray, other_vel_m_s: np.ndarray, other_radii_m: np.ndarray,
         self_index: np.ndarray, discs: np.ndarray, boxes: np.ndarray, dt_s: float,
         rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """One step of Eqs. (2)-(10) for the group; returns the new positions and velocities.

    ``pref_vel_m_s`` is ``v0 e`` (Eq. (2)); ``others_*`` every pedestrian the group reacts to (itself included,
    at ``self_index``; the robot too when the agents see it).
    """
    speed = np.hypot(pref_vel_m_s[:, 0], pref_vel_m_s[:, 1])
    e = np.divide(pref_vel_m_s, speed[:, None], out=np.zeros_like(pref_vel_m_s), where=speed[:, None] > 0)
    force = (pref_vel_m_s - vel_m_s) / TAU_S
    ped = pedestrian_forces(pos_m, radii_m, others_m, other_vel_m_s, other_radii_m, self_index)
    force = force + np.einsum("ak,akd->ad", sight_weight(e, ped), ped)
    border = border_forces(pos_m, radii_m, discs, boxes)
    if border.shape[1]:
        force = force + np.einsum("ak,akd->ad", sight_weight(e, border), border)
    angle = rng.uniform(0.0, 2.0 * math.pi, len(pos_m))
    size = rng.uniform(0.0, FLUCTUATION_M_S2, len(pos_m))
    force = force + size[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    w = vel_m_s + dt_s * force
    norm = np.hypot(w[:, 0], w[:, 1])
    cap = MAX_SPEED_FACTOR * v_pref_m_s
    v = np.where((norm > cap)[:, None], w * (cap / np.maximum(norm, 1e-12))[:, None], w)
    return pos_m + dt_s * v, v
