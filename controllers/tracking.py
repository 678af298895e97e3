"""Rangefinder hits of unknown obstacles -> tracked discs with velocities (no MuJoCo).

The simulation drops the hits that lie on the known map and hands the rest here
every control step, each with the position of the sensor that saw it.  The
tracker does only what the rays allow:

1. **Clusters** the hits by single linkage: two hits closer than
   ``2 * default_radius_m``, whose rays are less than ``max_link_angle_deg`` apart,
   may lie on one disc, so they join one cluster; unless (``split_seen_gaps``) a
   beam of the step crosses the segment between them with no hit before it.
2. **Fits a disc** to each cluster.  With three hits or more the radius is
   measured by a least-squares circle fit (Kasa 1976); otherwise it is the
   track's radius so far, or ``default_radius_m`` (the assumed obstacle
   radius), and never less than half the chord between the two hits farthest
   apart.  With one hit the centre lies one radius beyond the hit along the
   ray; with two or more it lies on the perpendicular bisector of the widest
   chord, on the side away from the sensors, one radius from both ends.
3. **Associates** clusters with tracks greedily by the distance of the
   cluster's hits from each track's rim (its disc predicted to now), within
   ``gate_m``; what is left starts a track.
4. **Updates with the prior**: one hit alone fixes only a point of the rim,
   not where the centre lies around it.  Taking "one radius beyond the hit
   along the ray" makes a disc the robot drives past appear to drive along
   with it (the beam's hit slides over its surface); for a track, the centre
   is instead the point one radius from the hit nearest the track's predicted
   centre, on the side the ray came from (the least change that explains the hit).
5. **Estimates the velocity** of each track as the least-squares slope of its
   centres over the last ``window_s`` (zero until two samples span ``min_span_s``);
   a centre more than ``jump_m`` from the predicted one restarts the window.  With
   ``hit_motion`` (default) the velocity is instead that of the disc fitted to the
   window's raw hits (:mod:`controllers.hit_motion`), when they fit one disc.
6. **Coasts** an unseen track (position predicted with its velocity) for
   ``keep_s``, then forgets it: an obstacle that slips between two beams, or out
   of range, is still reported for a moment; but when the beams are given
   (``beams``), a coasting track that a beam passes through, by more than
   ``clear_m`` inside its rim, without a hit before it, is contradicted and
   dropped at once (negative evidence).
7. **Merges** two tracks whose centres come closer than half the sum of their
   radii (one obstacle seen as two clusters): the older one stays.

Radii: a circle fit must lie within ``max_radius_m``; the track's radius is the
median of its fits (one stray fit no longer fixes it for good).

This is a choice of ours (the papers only say the sensors detect obstacles,
Abdulla & Hadi (2025) §5.2); the tolerances the tests hold it to are stated there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from swarmnav.controllers.hit_motion import fit_moving_disc
from swarmnav.controllers.navigator import DetectedObstacle


@dataclass
class _Track:
    track_id: int
    times_s: list[float] = field(default_factory=list)
    centres_m: list[tuple[float, float]] = field(default_factory=list)
    radius_m: float = 0.0
    measured: bool = False  # the radius came from a circle fit (else a lower bound or the default)
    fits_m: list[float] = field(default_factory=list)  # the radii of its circle fits
    velocity_m_s: tuple[float, float] = (0.0, 0.0)
    hit_times_s: list[float] = field(default_factory=list)  # every hit it took in the window, and when
    hits_m: list[tuple[float, float]] = field(default_factory=list)

    def predicted(self, time_s: float) -> tuple[float, float]:
        x, y = self.centres_m[-1]
        dt = time_s - self.times_s[-1]
        return x + self.velocity_m_s[0] * dt, y + self.velocity_m_s[1] * dt


@dataclass
class HitTracker:
    """Turns the unknown hits of successive steps into :class:`DetectedObstacle` estimates.

    Args:
        default_radius_m: assumed radius when the arc of hits is shorter (a lower bound otherwise).
        gate_m: largest distance between a track's predicted centre and a cluster it takes.
        window_s: span of the velocity fit.
        min_span_s: shortest span that gives a velocity (zero before).
        keep_s: how long an unseen track is still reported (coasting).
        max_speed_m_s: velocity estimates are clipped to this norm (a guard against fit noise).
        max_radius_m: circle fits larger than this are discarded (nearly collinear hits: a wall-like arc).
        clear_m: how far inside a coasting track's rim a beam must pass unhindered to contradict it.
        jump_m: a new centre this far from the predicted one restarts the velocity window.
        hit_motion: step 5 takes the velocity of the moving disc fitted to the window's raw hits
            (:func:`controllers.hit_motion.fit_moving_disc`, ours) instead of regressing the steps' centres;
            False: the regression alone.
        hit_motion_rms_m: a hit fit whose rim residual exceeds this (the hits are not one disc) is not used.
        max_link_angle_deg: step 1 links two hits only if their rays are less than this apart (ours; 180: off).
            A disc the robot is not touching subtends less than 90 degrees unless it is over 2.4 times the
            robot's radius; hits on two discs either side of the robot, closer than ``2 * default_radius_m``,
            made one phantom disc between them, over the robot (dyn-overtake-2).
        split_seen_gaps: step 1 never links two hits when a beam of the step (``beams``) crosses the segment
            between them, by more than ``clear_m`` from its ends, with no hit before it (ours; False: off).
            A disc with both hits on its rim contains that chord, so a free point on it means two obstacles:
            hits on two discs 0.4 m apart made one phantom disc over the gap between them, where the goal
            was (dyn-overtake-2).
    """

    default_radius_m: float = 0.3
    gate_m: float = 0.25
    window_s: float = 1.0
    min_span_s: float = 0.3
    keep_s: float = 1.0
    max_speed_m_s: float = 0.5
    max_radius_m: float = 0.6
    clear_m: float = 0.05
    jump_m: float = 0.3
    hit_motion: bool = True
    hit_motion_rms_m: float = 0.03
    max_link_angle_deg: float = 90.0
    split_seen_gaps: bool = True

    def __post_init__(self) -> None:
        self.reach_m = math.inf  # the beams' reach (set by the sensing); misses say nothing beyond it
        self.reset()

    def reset(self) -> None:
        self._tracks: list[_Track] = []
        self._next_id = 0

    # -- one step ------------------------------------------------------------
    def update(self, time_s: float, hits_m: np.ndarray, origins_m: np.ndarray,
               beams: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> tuple[DetectedObstacle, ...]:
        """Feed this step's unknown hits (N, 2) and their sensors' positions (N, 2); return the tracks.

        ``beams``: every beam of this step as (origins (K, 2), unit directions (K, 2),
        ranges (K,), ``inf`` where nothing was hit within reach, ranges capped at the reach
        otherwise): the negative evidence of step 6.  Without it tracks only coast.
        """
        hits = np.asarray(hits_m, dtype=float).reshape(-1, 2)
        origins = np.asarray(origins_m, dtype=float).reshape(-1, 2)
        clusters = [(hits[idx], origins[idx]) for idx in self._clusters(hits, origins, beams)]
        seen = self._associate(time_s, clusters)
        self._tracks = [t for t in self._tracks if time_s - t.times_s[-1] <= self.keep_s]
        if beams is not None:
            self._tracks = [t for t in self._tracks if t.track_id in seen or not self._contradicted(t, time_s, beams)]
        self._merge()
        out = []
        for t in self._tracks:
            x, y = t.predicted(time_s)
            out.append(DetectedObstacle(x, y, t.radius_m, t.velocity_m_s[0], t.velocity_m_s[1], t.track_id))
        return tuple(out)

    def _clusters(self, hits: np.ndarray, origins: np.ndarray,
                  beams: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> list[np.ndarray]:
        n = len(hits)
        if n == 0:
            return []
        near = np.hypot(*(hits[:, None, :] - hits[None, :, :]).transpose(2, 0, 1)) < 2.0 * self.default_radius_m
        if self.max_link_angle_deg < 180.0:
            rays = hits - origins
            rays /= np.maximum(np.linalg.norm(rays, axis=1, keepdims=True), 1e-12)
            near &= rays @ rays.T > math.cos(math.radians(self.max_link_angle_deg))
        if self.split_seen_gaps and beams is not None and len(beams[0]) and n > 1:
            near &= ~self._chord_seen_through(hits, beams)
        label = -np.ones(n, dtype=np.int64)
        clusters = []
        for i in range(n):
            if label[i] >= 0:
                continue
            label[i] = len(clusters)
            members, frontier = [i], [i]
            while frontier:
                j = frontier.pop()
                for k in np.flatnonzero(near[j] & (label < 0)):
                    label[k] = label[i]
                    members.append(int(k))
                    frontier.append(int(k))
            clusters.append(np.array(sorted(members)))
        return clusters

    def _chord_seen_through(self, hits: np.ndarray, beams: tuple[np.ndarray, np.ndarray, np.ndarray]) -> np.ndarray:
        """(N, N): a beam crosses the segment between hits i and j, by more than ``clear_m``, with no hit
        before it.  A disc through both hits contains that chord (it is convex), so they lie on two obstacles."""
        origins, directions, ranges = (np.asarray(b, dtype=float) for b in beams)
        p = hits[:, None, None, :]                              # (N, 1, 1, 2) one end
        e = hits[None, :, None, :] - p                          # (N, N, 1, 2) the chord
        w = p - origins[None, None, :, :]                       # (N, 1, K, 2)
        d = directions[None, None, :, :]
        det = d[..., 0] * e[..., 1] - d[..., 1] * e[..., 0]     # cross(d, e)
        ok = np.abs(det) > 1e-9
        safe = np.where(ok, det, 1.0)
        s = (w[..., 0] * e[..., 1] - w[..., 1] * e[..., 0]) / safe  # along the beam
        u = (w[..., 0] * d[..., 1] - w[..., 1] * d[..., 0]) / safe  # along the chord
        length = np.maximum(np.linalg.norm(e, axis=-1), 1e-12)
        margin = self.clear_m / length                          # keep clear of the chord's ends
        crossed = ok & (s > 0.0) & (u > margin) & (u < 1.0 - margin) & (ranges[None, None, :] > s + self.clear_m)
        return crossed.any(axis=2)

    def _fit(self, hits: np.ndarray, origins: np.ndarray, radius_m: float = 0.0
             ) -> tuple[float, float, float, bool]:
        """(x, y, radius, measured) of the disc the hits lie on (see the module docstring, step 2).

        ``radius_m``: the radius its track has shown so far, used when the hits cannot measure one.
        ``measured``: the radius came from a circle fit through three hits or more.
        """
        rays = hits - origins
        rays /= np.maximum(np.linalg.norm(rays, axis=1, keepdims=True), 1e-12)
        guess = radius_m if radius_m > 0 else self.default_radius_m
        if len(hits) == 1:
            c = hits[0] + guess * rays[0]
            return float(c[0]), float(c[1]), guess, False
        d = np.linalg.norm(hits[:, None, :] - hits[None, :, :], axis=2)
        i, j = np.unravel_index(int(np.argmax(d)), d.shape)
        chord = float(d[i, j])
        fitted = self._circle_radius(hits) if len(hits) >= 3 else None
        measured = fitted is not None
        r = max(fitted if measured else guess, 0.5 * chord)
        mid = 0.5 * (hits[i] + hits[j])
        along = (hits[j] - hits[i]) / max(chord, 1e-12)
        normal = np.array([-along[1], along[0]])
        if float(normal @ rays.mean(axis=0)) < 0.0:
            normal = -normal
        c = mid + math.sqrt(max(r * r - 0.25 * chord * chord, 0.0)) * normal
        return float(c[0]), float(c[1]), r, measured

    def _circle_radius(self, hits: np.ndarray) -> float | None:
        """Radius of the least-squares circle through the hits (Kasa's algebraic fit), or None if ill-posed."""
        p = hits - hits.mean(axis=0)
        a = np.column_stack([p, np.ones(len(p))])
        rhs = -(p ** 2).sum(axis=1)
        sol, _, rank, sv = np.linalg.lstsq(a, rhs, rcond=None)
        if rank < 3 or sv[-1] < 1e-6:
            return None
        cx, cy = -0.5 * sol[0], -0.5 * sol[1]
        r2 = cx * cx + cy * cy - sol[2]
        if not r2 > 0 or r2 > self.max_radius_m ** 2:
            return None
        return math.sqrt(r2)

    def _associate(self, time_s: float, clusters: list[tuple[np.ndarray, np.ndarray]]) -> set[int]:
        """Update the tracks with this step's clusters; the ids of the tracks seen."""
        pairs = []
        for ti, track in enumerate(self._tracks):
            px, py = track.predicted(time_s)
            for di, (hits, _) in enumerate(clusters):
                # How far the hits lie from the predicted rim (the track's disc now).
                gap = float(np.mean(np.abs(np.hypot(hits[:, 0] - px, hits[:, 1] - py) - track.radius_m)))
                if gap <= self.gate_m:
                    pairs.append((gap, ti, di))
        pairs.sort()
        used_t, used_d = set(), set()
        seen = set()
        for _, ti, di in pairs:
            if ti in used_t or di in used_d:
                continue
            used_t.add(ti)
            used_d.add(di)
            track = self._tracks[ti]
            hits, origins = clusters[di]
            if len(hits) == 1:
                fit = self._fit_one(hits[0], origins[0], track.predicted(time_s), track.radius_m)
            else:
                fit = self._fit(hits, origins, track.radius_m)
            self._observe(track, time_s, *fit, hits)
            seen.add(track.track_id)
        for di in range(len(clusters)):
            if di not in used_d:
                track = _Track(self._next_id)
                self._next_id += 1
                self._observe(track, time_s, *self._fit(*clusters[di]), clusters[di][0])
                self._tracks.append(track)
                seen.add(track.track_id)
        return seen

    @staticmethod
    def _fit_one(hit: np.ndarray, origin: np.ndarray, prior: tuple[float, float], radius_m: float
                 ) -> tuple[float, float, float, bool]:
        """Step 4: the centre one radius from the hit nearest the prior centre, on the ray's far side."""
        ray = hit - origin
        ray = ray / max(float(np.hypot(*ray)), 1e-12)
        toward = np.array(prior) - hit
        norm = float(np.hypot(*toward))
        u = toward / norm if norm > 1e-12 else ray
        along = float(u @ ray)
        if along < 0.0:  # the prior lies on the sensor's side of the hit: the rim point nearest it
            u = u - along * ray
            n = float(np.hypot(*u))
            u = u / n if n > 1e-12 else ray
        c = hit + radius_m * u
        return float(c[0]), float(c[1]), radius_m, False

    def _contradicted(self, track: _Track, time_s: float, beams: tuple[np.ndarray, np.ndarray, np.ndarray]) -> bool:
        """A beam passes through the track's predicted disc (shrunk by ``clear_m``) with no hit before it."""
        origins, directions, ranges = beams
        if not len(origins):
            return False
        r = track.radius_m - self.clear_m
        if r <= 0:
            return False
        px, py = track.predicted(time_s)
        d = np.array([px, py]) - origins                       # (K, 2)
        along = np.sum(d * directions, axis=1)
        miss2 = np.sum(d * d, axis=1) - along ** 2
        inside = miss2 < r * r
        entry = along - np.sqrt(np.maximum(r * r - miss2, 0.0))
        # Only beams whose reach covers the entry point say anything (a finite range or a miss = inf
        # means nothing was hit before that range; the caller caps misses at the reach).
        return bool(np.any(inside & (entry > 0.0) & (ranges > entry + self.clear_m) & (entry < self.reach_m)))

    def _merge(self) -> None:
        """Step 7: drop the younger of two tracks closer than half the sum of their radii."""
        keep: list[_Track] = []
        for track in sorted(self._tracks, key=lambda t: t.track_id):
            x, y = track.centres_m[-1]
            if all(math.hypot(x - k.centres_m[-1][0], y - k.centres_m[-1][1]) >= 0.5 * (track.radius_m + k.radius_m)
                   for k in keep):
                keep.append(track)
        self._tracks = keep

    def _observe(self, track: _Track, time_s: float, x: float, y: float, r: float, measured: bool,
                 hits: np.ndarray) -> None:
        if track.times_s:
            px, py = track.predicted(time_s)
            if math.hypot(x - px, y - py) > self.jump_m:
                # A jump (another part of the obstacle, or of another): the old centres say nothing
                # about the motion any more.
                track.times_s.clear()
                track.centres_m.clear()
                track.hit_times_s.clear()
                track.hits_m.clear()
                track.velocity_m_s = (0.0, 0.0)
        track.times_s.append(time_s)
        track.centres_m.append((x, y))
        track.hit_times_s.extend([time_s] * len(hits))
        track.hits_m.extend(map(tuple, hits))
        if measured:
            track.fits_m.append(r)
            del track.fits_m[:-20]
            track.radius_m, track.measured = float(np.median(track.fits_m)), True
        elif not track.measured:
            track.radius_m = max(track.radius_m, r)
        while track.times_s[0] < time_s - self.window_s:
            track.times_s.pop(0)
            track.centres_m.pop(0)
        while track.hit_times_s[0] < time_s - self.window_s:
            track.hit_times_s.pop(0)
            track.hits_m.pop(0)
        t = np.array(track.times_s)
        if t[-1] - t[0] < self.min_span_s:
            return
        c = np.array(track.centres_m)
        tc = t - t.mean()
        v = (tc @ (c - c.mean(axis=0))) / float(tc @ tc)
        if self.hit_motion:
            v = self._hit_motion(track, time_s, v)
        speed = float(np.hypot(v[0], v[1]))
        if speed > self.max_speed_m_s:
            v *= self.max_speed_m_s / speed
        track.velocity_m_s = (float(v[0]), float(v[1]))

    def _hit_motion(self, track: _Track, time_s: float, regressed_m_s: np.ndarray) -> np.ndarray:
        """Step 5 with ``hit_motion``: the velocity of the disc through the window's raw hits (the step's
        centre stays: replacing it too changed little on dyn300 and lost dyn-overtake-2); the regressed velocity
        when the hits do not fit one moving disc."""
        centre, velocity, rms = fit_moving_disc(np.array(track.hit_times_s), np.array(track.hits_m),
                                                track.radius_m, time_s, np.array(track.centres_m[-1]),
                                                np.array(track.velocity_m_s))
        if rms > self.hit_motion_rms_m or math.hypot(*(centre - track.centres_m[-1])) > self.jump_m:
            return regressed_m_s
        return velocity
