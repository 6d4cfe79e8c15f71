#!/usr/bin/env python3
"""A forger of leading values, with nothing but the eclipse-zenoh package.

Subscribes to a leader's samples (tandem/<cell>/lv/<leader>) and, for each real sample,
publishes on the same key: one stamped an hour in the future, one for the next cycle a few
units off (ahead of the real one: a jump), a replay of an older one and one whose sequence
number does not match its time. Also records the last health of a node and the gateways'
counters. Prints one JSON summary on stdout.

  forge.py --cell x --leader master --node nb --connect tcp/10.0.0.1:7447 --seconds 8
"""
import argparse
import json
import struct
import threading
import time

import zenoh

# LeadingValueSample on Zenoh: t, seq, p, v, a, modulo start, modulo length, status, leader.
FMT = "<qqdddddII"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cell", required=True)
    ap.add_argument("--leader", required=True)
    ap.add_argument("--node", required=True, help="the follower's node whose health is recorded")
    ap.add_argument("--connect", action="append", default=[])
    ap.add_argument("--seconds", type=float, default=8.0)
    ap.add_argument("--cycle-ns", type=int, default=1_000_000)
    ap.add_argument("--jump", type=float, default=5.0)
    ap.add_argument("--after", type=float, default=1.0,
                    help="forge only once the leader's samples flowed this long (s): the gate's reference is then a real sample")
    a = ap.parse_args()

    conf = zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    if a.connect:
        conf.insert_json5("connect/endpoints", json.dumps(a.connect))
        conf.insert_json5("scouting/multicast/enabled", "false")
    session = zenoh.open(conf)
    key = f"tandem/{a.cell}/lv/{a.leader}"
    pub = session.declare_publisher(key)
    lock = threading.Lock()
    state = {"real": 0, "forged": 0, "health": None, "gateways": {}}
    queue = []

    def on_sample(sample):
        b = bytes(sample.payload.to_bytes())
        if len(b) != struct.calcsize(FMT):
            return
        with lock:
            queue.append(struct.unpack(FMT, b))

    def on_watch(sample):
        k = str(sample.key_expr)
        try:
            j = json.loads(sample.payload.to_string())
        except ValueError:
            return
        with lock:
            if k.endswith("/health"):
                state["health"] = j
            elif "/gateway/" in k:
                state["gateways"][k.rsplit("/", 1)[-1]] = j

    # Remote only: never our own forgeries.
    sub = session.declare_subscriber(key, on_sample, allowed_origin=zenoh.Locality.REMOTE)
    watch_h = session.declare_subscriber(f"tandem/{a.cell}/{a.node}/health", on_watch)
    watch_g = session.declare_subscriber(f"tandem/{a.cell}/gateway/*", on_watch)
    end = time.monotonic() + a.seconds
    hour = 3600 * 1_000_000_000
    c = a.cycle_ns
    last_seq = -1
    first = None
    while time.monotonic() < end:
        with lock:
            real = queue[:]
            queue.clear()
        for (t, seq, p, v, acc, ms, ml, st, leader) in real:
            # Each real sample once (another forger's would be on the grid too).
            if seq * c != t or seq <= last_seq:
                continue
            last_seq = seq
            if first is None:
                first = t
            if t - first < a.after * 1e9:
                continue
            forged = [
                (t + hour, seq + hour // c, p, v, acc, ms, ml, st, leader),
                (t + c, seq + 1, p + a.jump, v, acc, ms, ml, st, leader),
                (t - 10 * c, seq - 10, p, v, acc, ms, ml, st, leader),
                (t, seq + 7, p, v, acc, ms, ml, st, leader),
            ]
            for f in forged:
                pub.put(struct.pack(FMT, *f))
            with lock:
                state["real"] += 1
                state["forged"] += len(forged)
        time.sleep(0.0002)
    # The last health after the forging stopped.
    time.sleep(1.0)
    with lock:
        print(json.dumps(state))
    session.close()


if __name__ == "__main__":
    main()
