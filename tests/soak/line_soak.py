#!/usr/bin/env python3
"""Soak runner of issue 12: the bundled line cell (config/line.toml) under `tandem up` with
`--record`, for an hour by default, on this machine as it is (other builds may run beside it:
that is the point). Not a CI test; run it by hand and report its figures:

    cargo build --release --workspace --bins
    python3 tests/soak/line_soak.py --minutes 60 --out /tmp/line-soak

It writes a script (config/line-script.toml's couplings, then the line's velocity changed every
20 s for the whole run), runs `tandem up config/line.toml --script ... --record OUT/record`,
and prints what the nodes said: alarms (601 above all), cycles, overruns, skipped cycles,
leading values extrapolated and lost, the lateness and compute summaries, rows and lines the
recorder lost. Exit status 0 only when no alarm was raised and every node ran to the end.
"""

import argparse
import os
import re
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def script(minutes: float) -> str:
    """config/line-script.toml with the run's duration and a velocity change every 20 s."""
    src = (ROOT / "config/line-script.toml").read_text()
    seconds = minutes * 60.0
    src = re.sub(r"(?m)^duration = .*$", f"duration = {seconds}", src, count=1)
    speeds = [1000.0, 1500.0, 600.0, 1200.0]
    t, k = 20.0, 0
    more = []
    while t < seconds - 1.0:
        more.append(
            f'\n[[at]]\nt = {t}\naxis = "line"\ninstruction = "MC_MoveVelocity"\n'
            f"velocity = {speeds[k % len(speeds)]}\n"
        )
        t += 20.0
        k += 1
    return src + "".join(more)


def summary(out: str) -> dict:
    """The figures of the nodes' lines in `tandem up`'s output."""
    s = {
        "alarms": [l for l in out.splitlines() if " alarm " in l and "t=" in l],
        "stopped": re.findall(r"\[(\w+)\].*stopped after (\d+) cycles \((\d+) overruns, "
                              r"(\d+) leading values extrapolated, (\d+) leading-value samples "
                              r"lost, (\d+) refused", out),
        "lateness": re.findall(r"\[(\w+)\].*lateness (p50 [^;\n]*?µs)", out),
        "compute": re.findall(r"\[(\w+)\].*compute (p50 [^;\n]*?µs)", out),
        "skipped": re.findall(r"\[(\w+)\].*cycle overflow: (.*)", out),
        "recording": [l for l in out.splitlines() if "recording lost" in l or "recording ended" in l],
        "crashed": [l for l in out.splitlines() if "crashed" in l or "stalled" in l],
    }
    return s


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--minutes", type=float, default=60.0)
    p.add_argument("--out", type=Path, default=Path("/tmp/line-soak"))
    p.add_argument("--tandem", type=Path, default=ROOT / "target/release/tandem")
    a = p.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)
    sc = a.out / "soak-script.toml"
    sc.write_text(script(a.minutes))
    cmd = [str(a.tandem), "up", str(ROOT / "config/line.toml"), "--script", str(sc),
           "--record", str(a.out / "record"), "--no-view"]
    print("running:", " ".join(cmd), flush=True)
    t0 = time.monotonic()
    # The run's own length plus a generous margin for start and stop: never wait forever.
    limit = a.minutes * 60.0 + 300.0
    with open(a.out / "up.log", "w") as log:
        try:
            r = subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT, timeout=limit,
                               env={**os.environ, "TANDEM_LOG": "info"})
            code = r.returncode
        except subprocess.TimeoutExpired:
            code = None
    out = (a.out / "up.log").read_text(errors="replace")
    s = summary(out)
    print(f"tandem up exit {code} after {time.monotonic() - t0:.0f} s; log {a.out / 'up.log'}")
    for node, cycles, overruns, extrap, lost, refused in s["stopped"]:
        print(f"  {node}: {cycles} cycles, {overruns} overruns, {extrap} extrapolated, "
              f"{lost} samples lost, {refused} refused")
    for node, lat in s["lateness"]:
        print(f"  {node} lateness {lat}")
    for node, c in s["compute"]:
        print(f"  {node} compute {c}")
    for node, what in s["skipped"]:
        print(f"  {node} cycle overflow: {what}")
    for l in s["recording"] + s["crashed"]:
        print("  " + l)
    print(f"  alarms: {len(s['alarms'])}")
    for l in s["alarms"][:20]:
        print("    " + l)
    ok = code == 0 and not s["alarms"] and len(s["stopped"]) == 3
    print("soak:", "passed" if ok else "FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
