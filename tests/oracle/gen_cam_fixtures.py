#!/usr/bin/env python3
"""Independent oracle for the cam motion laws.

Writes shared/motion/tests/fixtures/cam_laws.csv with cam-law samples computed by
the `pyplcopen` package (pinned in tests/oracle/requirements.txt,
pyplcopen==0.21.0). Regenerate with:

    pip install -r tests/oracle/requirements.txt
    python3 tests/oracle/gen_cam_fixtures.py [--out PATH]

The output is deterministic (fixed cases plus random.Random(20261123) draws,
fixed pyplcopen version).

What pyplcopen offers
---------------------
pyplcopen 0.21.0 is a compiled module; its only cam-law entry point is
    generate_cam_law(law: str, master_span: float, rise: float, points: int)
        -> list[(x, y)]
It has no docstring listing the laws. Unknown names raise
"RuntimeError: unknown cam law: <name>"; probing (PROBE_NAMES below, the names
tandem uses and the usual aliases) finds exactly three accepted names:
    cycloidal      -> tandem MotionLaw::Cycloid     s = u - sin(2 pi u)/(2 pi)
    modified_sine  -> tandem MotionLaw::ModifiedSine (VDI 2143 form, 1/(4+pi))
    poly345        -> tandem MotionLaw::Poly5        s = 10u^3 - 15u^4 + 6u^5
The generator asserts that this set is unchanged. Valid arguments (found by
probing; anything else raises "invalid_argument: a parameter value is out of
its valid domain"): master_span > 0, any finite rise (negative and 0 too),
8 <= points <= 64. The samples are x_i = master_span * (i / (points - 1)) and
y_i = rise * s(i / (points - 1)), i = 0 .. points-1.

CSV columns: law,master_span,rise,points,i,x,y
  law is pyplcopen's name; floats are written with repr(), so Rust's
  f64::from_str reads them exactly.
"""

import os
import random
import sys

import pyplcopen

EXPECTED_VERSION = "0.21.0"
SEED = 20261123
HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
OUT = os.path.join(REPO, "shared", "motion", "tests", "fixtures", "cam_laws.csv")
# `--out PATH` writes elsewhere (to regenerate into a temp file and compare).
if len(sys.argv) == 3 and sys.argv[1] == "--out":
    OUT = os.path.abspath(sys.argv[2])
COLUMNS = ["law", "master_span", "rise", "points", "i", "x", "y"]

LAWS = ["cycloidal", "modified_sine", "poly345"]
PROBE_NAMES = [
    # tandem's names
    "straight_line", "quadratic_parabola", "poly5", "simple_sine", "cycloid",
    "modified_sine", "modified_trapezoid", "modified_acceleration_trapezoid",
    "inclined_sine", "poly7",
    # usual aliases
    "linear", "line", "constant_velocity", "parabolic", "parabola",
    "poly345", "poly3-4-5", "3-4-5", "poly4567", "poly4-5-6-7", "4-5-6-7",
    "harmonic", "simple_harmonic", "sine", "cosine", "cycloidal",
    "modified_trapezoidal", "trapezoidal", "modified_sinusoidal",
    "double_harmonic", "bestehorn",
    # case variants
    "Cycloidal", "CYCLOIDAL", "Poly345", "ModifiedSine", "modified-sine",
]

FIXED_CASES = [  # (master_span, rise, points)
    (1.0, 1.0, 64),
    (360.0, 100.0, 61),
    (2.5, -3.0, 8),
    (0.001, 1000.0, 33),
    (7.0, 0.0, 9),
]
N_RANDOM = 8  # per law


def accepted(name):
    try:
        pyplcopen.generate_cam_law(name, 1.0, 1.0, 11)
        return True
    except RuntimeError as e:
        if "unknown cam law" not in str(e):
            raise
        return False


def main():
    version = getattr(pyplcopen, "__version__", None)
    if version is None:
        from importlib.metadata import version as dist_version
        version = dist_version("pyplcopen")
    if version != EXPECTED_VERSION:
        print("warning: pyplcopen %s installed, fixtures pinned to %s"
              % (version, EXPECTED_VERSION), file=sys.stderr)
    found = sorted(n for n in PROBE_NAMES if accepted(n))
    if found != sorted(LAWS):
        sys.exit("pyplcopen accepts %s, expected %s" % (found, sorted(LAWS)))

    rng = random.Random(SEED)
    rows = []
    for law in LAWS:
        cases = list(FIXED_CASES)
        for _ in range(N_RANDOM):
            span = 10.0 ** rng.uniform(-3.0, 4.0)
            rise = rng.choice([1.0, -1.0]) * 10.0 ** rng.uniform(-3.0, 3.0)
            points = rng.randint(8, 64)
            cases.append((span, rise, points))
        for span, rise, points in cases:
            samples = pyplcopen.generate_cam_law(law, span, rise, points)
            if len(samples) != points:
                sys.exit("%s: %d samples for points=%d" % (law, len(samples), points))
            for i, (x, y) in enumerate(samples):
                rows.append([law, repr(float(span)), repr(float(rise)), str(points),
                             str(i), repr(float(x)), repr(float(y))])

    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w", newline="\n") as f:
        f.write(",".join(COLUMNS) + "\n")
        for r in rows:
            f.write(",".join(r) + "\n")
    print("pyplcopen %s accepts: %s" % (version, ", ".join(found)))
    print("wrote %d rows to %s" % (len(rows), os.path.relpath(OUT, REPO)))


if __name__ == "__main__":
    main()
