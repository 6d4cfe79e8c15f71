#!/usr/bin/env python3
"""Plots a `tandem sim` trace (the README picture).

    cargo run --release -p tandem -- sim config/example-cell.toml \
        --script config/example-script.toml --trace trace.csv -q
    python3 docs/img/plot_trace.py trace.csv docs/img/example-trace.png

Needs matplotlib (pip install matplotlib); not used by the tests.
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(src, dst):
    with open(src) as f:
        rows = list(csv.DictReader(f))
    t = [float(r["time_s"]) for r in rows]
    col = lambda name: [float(r[name]) for r in rows]  # noqa: E731
    fig, ax = plt.subplots(4, 1, figsize=(10, 9), sharex=True)
    ax[0].plot(t, col("slide.position"), label="slide position setpoint (mm)")
    ax[0].plot(t, col("slide.actual_position"), "--", label="slide actual (mm)")
    ax[0].legend(loc="upper left")
    ax[1].plot(t, col("slide.velocity"), label="slide velocity (mm/s)")
    ax[1].plot(t, [1000 * x for x in col("slide.following_error")], label="following error (µm)")
    ax[1].legend(loc="upper left")
    ax[2].plot(t, col("table.position"), label="table position (°, modulo 360)")
    ax[2].legend(loc="upper left")
    ax[3].plot(t, col("conveyor.velocity"), label="conveyor velocity (°/s)")
    ax[3].legend(loc="upper left")
    ax[3].set_xlabel("virtual time (s)")
    fig.suptitle("tandem sim config/example-cell.toml --script config/example-script.toml")
    fig.tight_layout()
    fig.savefig(dst, dpi=80)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
