#!/usr/bin/env python3
"""Independent oracle for the 1-DoF jerk-limited trajectory generator.

Writes shared/motion/tests/fixtures/ruckig_1dof.csv with time-optimal durations
computed by the `ruckig` package (pinned in tests/oracle/requirements.txt,
ruckig==0.19.4). Regenerate with:

    pip install -r tests/oracle/requirements.txt
    python3 tests/oracle/gen_ruckig_fixtures.py

The output is deterministic (random.Random(20261122), fixed ruckig version).

CSV columns: id,kind,p0,v0,a0,target,vmax,acc,dec,jerk,duration
  kind = pos : move to position `target` and stop there (target velocity 0,
               target acceleration 0; ruckig ControlInterface.Position).
  kind = vel : reach velocity `target` with acceleration 0; the final position
               is free (ruckig ControlInterface.Velocity).
  jerk = inf : trapezoidal profile (ruckig max_jerk = inf; acceleration may
               jump). a0 is always 0 in these rows.
All floats are written with repr(), so Rust's f64::from_str parses them exactly
("inf" included). `duration` is ruckig's Trajectory.duration in seconds.

Limit semantics
---------------
Ours (Siemens S7-1500T style): |v| <= vmax; `acc` bounds |a| while |v|
increases (speeding up), `dec` bounds |a| while |v| decreases (braking);
|j| <= jerk.
Ruckig's are sign based: min_acceleration <= a <= max_acceleration.
The two agree whenever the velocity keeps one sign over the whole trajectory:
  v >= 0 throughout: max_acceleration = acc, min_acceleration = -dec
  v <= 0 throughout: max_acceleration = dec, min_acceleration = -acc
and they always agree when acc == dec.
Hence every case is either
  * symmetric (acc == dec, about half of the rows): any direction, overshoot
    and reversal allowed; or
  * asymmetric: an intended direction d = +/-1 is drawn, ruckig is run with the
    matching mapping above, the trajectory is sampled densely (2001 uniform
    points, every section boundary and every interior velocity extremum, via
    Trajectory.at_time) and the case is kept only if d*v(t) >= -1e-9*vmax
    everywhere; otherwise it is discarded and redrawn.
Caveat: for an asymmetric case the Siemens feasible set also contains
non-one-signed trajectories that ruckig's sign-based problem does not; the
fixtures assume (as intended) that the one-signed ruckig optimum is also the
Siemens optimum.

Start states are strictly inside the limits and no limit is inevitably
violated: |v0| < vmax, |a0| < the bound that applies (acc when speeding up or
from v0 = 0, dec when braking) and the "natural" velocity
v0 + a0*|a0|/(2*jerk) lies inside (-vmax, vmax).
Every kept trajectory is also checked (on the same samples) against |v| <= vmax
and the Siemens acc/dec bounds, with a relative tolerance of 1e-9.

A draw is skipped (and redrawn) when ruckig does not return Working/Finished,
when the final state at t = duration misses the target (position by more than
1e-8*max(1,|target|), velocity by more than 1e-8*vmax, acceleration by more
than 1e-8*max(acc,dec)), or when a limit check fails. Counts are printed.

Infinite jerk: supported by ruckig 0.19.4 (max_jerk = inf gives the
acceleration-limited trapezoidal / triangular profile). As a sanity check each
inf-jerk duration is compared with ruckig's duration for jerk = 1e7*max(acc,dec)
(which must be >= it and larger by at most 1e-4*T + 4e-7 s, the smoothing of
the acceleration corners); a mismatch is a skip reason too.
"""

import math
import os
import random
import sys
from collections import Counter

import ruckig
from ruckig import ControlInterface, InputParameter, Result, Ruckig, Trajectory

EXPECTED_RUCKIG_VERSION = "0.19.4"
SEED = 20261122

N_POS = 1200
N_VEL = 600
N_POS_INF = 200
N_VEL_INF = 100

INF = float("inf")
HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
OUT = os.path.join(REPO, "shared", "motion", "tests", "fixtures", "ruckig_1dof.csv")
# `--out PATH` writes elsewhere (tests/run.sh regenerates into a temp file and compares).
if len(sys.argv) == 3 and sys.argv[1] == "--out":
    OUT = os.path.abspath(sys.argv[2])
COLUMNS = ["id", "kind", "p0", "v0", "a0", "target", "vmax", "acc", "dec", "jerk", "duration"]

N_SAMPLES = 2001
SIGN_TOL = 1e-9  # relative to vmax
LIMIT_TOL = 1e-9  # relative tolerance of the limit checks
FINAL_TOL = 1e-8  # relative tolerance of the final state


def log_uniform(rng, lo, hi):
    return math.exp(rng.uniform(math.log(lo), math.log(hi)))


def ruckig_limits(acc, dec, direction):
    """(max_acceleration, min_acceleration) for the intended direction."""
    if direction >= 0:
        return acc, -dec
    return dec, -acc


def solve(kind, p0, v0, a0, target, vmax, amax, amin, jerk):
    inp = InputParameter(1)
    if kind == "vel":
        inp.control_interface = ControlInterface.Velocity
        inp.target_position = [0.0]
        inp.target_velocity = [target]
    else:
        inp.control_interface = ControlInterface.Position
        inp.target_position = [target]
        inp.target_velocity = [0.0]
    inp.target_acceleration = [0.0]
    inp.current_position = [p0]
    inp.current_velocity = [v0]
    inp.current_acceleration = [a0]
    inp.max_velocity = [vmax]
    inp.min_velocity = [-vmax]
    inp.max_acceleration = [amax]
    inp.min_acceleration = [amin]
    inp.max_jerk = [jerk]
    otg = Ruckig(1)
    traj = Trajectory(1)
    try:
        res = otg.calculate(inp, traj)
    except Exception as exc:  # ruckig raises on invalid input
        return ("exception: %s" % type(exc).__name__), None
    return res, traj


def state(traj, t):
    p, v, a = traj.at_time(t)
    return p[0], v[0], a[0]


def sample_times(traj):
    """Dense grid + section boundaries + interior velocity extrema."""
    T = traj.duration
    times = set(T * i / (N_SAMPLES - 1) for i in range(N_SAMPLES))
    prof = traj.profiles[0][0]
    segments = []  # (t_start, durations, a_starts, jerks)
    t0 = 0.0
    brake = prof.brake
    segments.append((t0, list(brake.t), list(brake.a), list(brake.j)))
    t0 += brake.duration
    segments.append((t0, list(prof.t), list(prof.a), list(prof.j)))
    t0 += sum(prof.t)
    accel = prof.accel
    segments.append((t0, list(accel.t), list(accel.a), list(accel.j)))
    for start, durs, accs, jerks in segments:
        t = start
        for k, d in enumerate(durs):
            times.add(t)
            if d > 0 and k < len(jerks) and jerks[k] != 0 and math.isfinite(jerks[k]):
                tau = -accs[k] / jerks[k]
                if 0 < tau < d:
                    times.add(t + tau)
            t += d
        times.add(t)
    return sorted(x for x in times if 0.0 <= x <= T)


def check_samples(traj, vmax, acc, dec, direction):
    """Returns None if fine, else a reason string."""
    bigger = max(acc, dec)
    for t in sample_times(traj):
        _, v, a = state(traj, t)
        if direction != 0 and direction * v < -SIGN_TOL * vmax:
            return "sign_change"
        if abs(v) > vmax * (1 + LIMIT_TOL):
            return "vmax_exceeded"
        if abs(v) <= SIGN_TOL * vmax:
            bound = bigger  # at v ~ 0 the speeding-up/braking split is ill defined
        elif v * a > 0:
            bound = acc
        else:
            bound = dec
        if abs(a) > bound * (1 + LIMIT_TOL):
            return "acc_dec_exceeded"
    return None


def draw_case(rng, kind, symmetric, inf_jerk):
    vmax = log_uniform(rng, 1.0, 2000.0)
    acc = log_uniform(rng, 10.0, 20000.0)
    dec = acc if symmetric else log_uniform(rng, 10.0, 20000.0)
    jerk = INF if inf_jerk else acc * log_uniform(rng, 1.0, 200.0)
    direction = 0 if symmetric else rng.choice((-1, 1))

    p0 = 0.0 if rng.random() < 0.25 else rng.choice((-1, 1)) * log_uniform(rng, 1e-3, 1e3)

    # start velocity / acceleration
    if rng.random() < 1.0 / 3.0:
        v0, a0 = 0.0, 0.0
    else:
        frac = rng.uniform(0.0, 0.99)
        s = direction if direction != 0 else rng.choice((-1, 1))
        v0 = s * frac * vmax
        a0 = 0.0
        if not inf_jerk and rng.random() < 0.5:
            for _ in range(100):
                sa = rng.choice((-1, 1))
                if v0 == 0.0 and direction != 0:
                    sa = direction
                speeding_up = v0 == 0.0 or (v0 > 0) == (sa > 0)
                bound = acc if speeding_up else dec
                cand = sa * rng.uniform(0.01, 0.99) * bound
                natural = v0 + cand * abs(cand) / (2.0 * jerk)
                if abs(natural) < vmax:
                    a0 = cand
                    break

    amax, amin = (acc, -acc) if symmetric else ruckig_limits(acc, dec, direction)

    if kind == "vel":
        u = rng.random()
        at_rest = v0 == 0.0 and a0 == 0.0
        if u < 0.15 and not at_rest:  # stop (no trivial zero-duration rest->0 rows)
            target = 0.0
        elif u < 0.20:
            s = direction if direction != 0 else rng.choice((-1, 1))
            target = s * vmax
        else:
            if direction != 0:
                target = direction * rng.uniform(0.0, 1.0) * vmax
            else:
                target = rng.uniform(-1.0, 1.0) * vmax
    else:
        u = rng.random()
        mode = "free"
        if symmetric:
            if u < 0.2:
                mode = "short"
            elif u < 0.35:
                mode = "behind"
        elif u < 0.3:
            mode = "short"
        if mode == "short":
            # relative to the stopping point reached by braking right away
            res, tr = solve("vel", 0.0, v0, a0, 0.0, vmax, amax, amin, jerk)
            stop = state(tr, tr.duration)[0] if tr is not None else 0.0
            if abs(stop) < 0.01:
                s = direction if direction != 0 else rng.choice((-1, 1))
                dist = s * log_uniform(rng, 0.01, 1.0)
            elif symmetric:
                dist = stop * rng.uniform(0.0, 1.5)  # < 1: inside braking distance
            else:
                dist = stop * rng.uniform(0.3, 3.0)
        elif mode == "behind":
            s = -math.copysign(1.0, v0) if v0 != 0.0 else rng.choice((-1, 1))
            dist = s * log_uniform(rng, 0.01, 5000.0)
        else:
            s = direction if direction != 0 else rng.choice((-1, 1))
            dist = s * log_uniform(rng, 0.01, 5000.0)
        target = p0 + dist
    return dict(kind=kind, p0=p0, v0=v0, a0=a0, target=target, vmax=vmax,
                acc=acc, dec=dec, jerk=jerk, direction=direction,
                amax=amax, amin=amin)


def evaluate(c):
    """Returns (duration, None) or (None, reason)."""
    res, traj = solve(c["kind"], c["p0"], c["v0"], c["a0"], c["target"],
                      c["vmax"], c["amax"], c["amin"], c["jerk"])
    if traj is None:
        return None, str(res)
    if res not in (Result.Working, Result.Finished):
        return None, "result_%s" % res.name if hasattr(res, "name") else str(res)
    T = traj.duration
    if not (math.isfinite(T) and T >= 0.0):
        return None, "bad_duration"
    p, v, a = state(traj, T)
    if c["kind"] == "pos":
        if abs(p - c["target"]) > FINAL_TOL * max(1.0, abs(c["target"])):
            return None, "final_position"
        if abs(v) > FINAL_TOL * c["vmax"]:
            return None, "final_velocity"
    else:
        if abs(v - c["target"]) > FINAL_TOL * c["vmax"]:
            return None, "final_velocity"
    if abs(a) > FINAL_TOL * max(c["acc"], c["dec"]):
        return None, "final_acceleration"
    why = check_samples(traj, c["vmax"], c["acc"], c["dec"], c["direction"])
    if why is not None:
        return None, why
    if math.isinf(c["jerk"]):
        big = 1e7 * max(c["acc"], c["dec"])
        res2, tr2 = solve(c["kind"], c["p0"], c["v0"], c["a0"], c["target"],
                          c["vmax"], c["amax"], c["amin"], big)
        if tr2 is None or res2 not in (Result.Working, Result.Finished):
            return None, "inf_jerk_crosscheck_failed"
        T2 = tr2.duration
        # each acceleration corner costs O(a/j) = O(1e-7 s) with the finite jerk
        if not (T2 >= T * (1 - 1e-12) and T2 - T <= 1e-4 * T + 4e-7):
            return None, "inf_jerk_crosscheck_mismatch"
    return T, None


def main():
    if ruckig.__version__ != EXPECTED_RUCKIG_VERSION:
        print("warning: ruckig %s installed, fixtures pinned to %s"
              % (ruckig.__version__, EXPECTED_RUCKIG_VERSION), file=sys.stderr)
    rng = random.Random(SEED)
    groups = [("pos", False, N_POS), ("vel", False, N_VEL),
              ("pos", True, N_POS_INF), ("vel", True, N_VEL_INF)]
    rows = []
    skipped = Counter()
    rejected_asym = Counter()
    stats = Counter()
    for kind, inf_jerk, count in groups:
        label = "%s/%s" % (kind, "inf" if inf_jerk else "jerk")
        for k in range(count):
            symmetric = (k % 2 == 0)
            while True:
                c = draw_case(rng, kind, symmetric, inf_jerk)
                T, why = evaluate(c)
                if why is None:
                    break
                if why == "sign_change" and not symmetric:
                    rejected_asym[label] += 1
                else:
                    skipped[(label, why)] += 1
            stats[(label, "sym" if symmetric else "asym")] += 1
            if c["v0"] == 0.0 and c["a0"] == 0.0:
                stats[(label, "rest_start")] += 1
            rows.append((kind, c, T))

    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w", newline="\n") as f:
        f.write(",".join(COLUMNS) + "\n")
        for i, (kind, c, T) in enumerate(rows):
            fields = [str(i), kind] + [repr(float(c[n])) for n in
                                        ("p0", "v0", "a0", "target", "vmax", "acc", "dec", "jerk")]
            fields.append(repr(float(T)))
            f.write(",".join(fields) + "\n")

    print("wrote %d rows to %s" % (len(rows), os.path.relpath(OUT, REPO)))
    for kind, inf_jerk, count in groups:
        label = "%s/%s" % (kind, "inf" if inf_jerk else "jerk")
        print("  %-9s %4d rows (sym %d, asym %d, rest-start %d)" % (
            label, count, stats[(label, "sym")], stats[(label, "asym")],
            stats[(label, "rest_start")]))
    print("asymmetric draws rejected (velocity changed sign): %d  %s"
          % (sum(rejected_asym.values()), dict(rejected_asym)))
    print("skipped draws: %d" % sum(skipped.values()))
    for (label, why), n in sorted(skipped.items()):
        print("  %-9s %-28s %d" % (label, why, n))


if __name__ == "__main__":
    main()
