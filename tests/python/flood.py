#!/usr/bin/env python3
"""A command flood against a tandem cell, with nothing but the eclipse-zenoh package.

One sender (`flood`) sends --flood commands spread over --seconds while another (`operator`)
sends --operator commands over the same time, each a Zenoh query to
tandem/<cell>/<key>/cmd/<sender> (the sender in the key, as the access control of an mTLS cell
binds it to the certificate). Prints one JSON summary on stdout: per sender the replies by
outcome, the queries that got no reply, and the reply times (p50, p99, max in ms).

  flood.py --cell glue --connect tcp/127.0.0.1:7447 --key packer/conveyor --text MC_Reset
"""
import argparse
import json
import threading
import time

import zenoh


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cell", required=True)
    ap.add_argument("--connect", action="append", default=[])
    ap.add_argument("--key", required=True, help="<node>/<object>")
    ap.add_argument("--text", required=True)
    ap.add_argument("--flood", type=int, default=10000)
    ap.add_argument("--operator", type=int, default=50)
    ap.add_argument("--seconds", type=float, default=10.0)
    ap.add_argument("--wait", type=float, default=60.0, help="how long to wait for the gateway and the replies")
    a = ap.parse_args()

    conf = zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    if a.connect:
        conf.insert_json5("connect/endpoints", json.dumps(a.connect))
        conf.insert_json5("scouting/multicast/enabled", "false")
    session = zenoh.open(conf)
    key = f"tandem/{a.cell}/{a.key}/cmd"

    lock = threading.Lock()
    outcomes = {"flood": {}, "operator": {}, "probe": {}}
    replied = {"flood": 0, "operator": 0, "probe": 0}
    # Reply times (s) of each sender's queries: from the get to its (first) reply.
    latency = {"flood": [], "operator": [], "probe": []}

    def handler(sender):
        sent = time.monotonic()

        def on_reply(reply):
            took = time.monotonic() - sent
            if reply.ok is not None:
                try:
                    o = json.loads(reply.ok.payload.to_string()).get("outcome", "?")
                except ValueError:
                    o = "malformed"
            else:
                o = "error"
            with lock:
                outcomes[sender][o] = outcomes[sender].get(o, 0) + 1
                replied[sender] += 1
                latency[sender].append(took)
        return on_reply

    def send(sender):
        session.get(f"{key}/{sender}", handler(sender), payload=a.text, timeout=a.wait)

    # The gateway first: probe until one reply comes.
    deadline = time.monotonic() + a.wait
    while time.monotonic() < deadline:
        n = replied["probe"]
        send("probe")
        t = time.monotonic() + 1.0
        while time.monotonic() < t and replied["probe"] == n:
            time.sleep(0.01)
        if replied["probe"] > n:
            break

    def pace(sender, count):
        t0 = time.monotonic()
        for i in range(count):
            at = t0 + a.seconds * i / count
            d = at - time.monotonic()
            if d > 0:
                time.sleep(d)
            send(sender)

    started = time.monotonic()
    th = [threading.Thread(target=pace, args=("flood", a.flood)),
          threading.Thread(target=pace, args=("operator", a.operator))]
    for t in th:
        t.start()
    for t in th:
        t.join()
    sent_s = time.monotonic() - started
    deadline = time.monotonic() + a.wait
    while time.monotonic() < deadline:
        with lock:
            if replied["flood"] >= a.flood and replied["operator"] >= a.operator:
                break
        time.sleep(0.05)
    def ms(xs):
        """p50, p99 and max of reply times, in ms (None without replies)."""
        if not xs:
            return None
        xs = sorted(xs)
        at = lambda q: xs[min(len(xs) - 1, int(q * len(xs)))]
        return {"p50": at(0.5) * 1e3, "p99": at(0.99) * 1e3, "max": xs[-1] * 1e3}

    with lock:
        print(json.dumps({
            "reply_ms": {"flood": ms(latency["flood"]), "operator": ms(latency["operator"])},
            "flood": outcomes["flood"],
            "operator": outcomes["operator"],
            "missing": {"flood": a.flood - replied["flood"], "operator": a.operator - replied["operator"]},
            "probe": outcomes["probe"],
            "sent_s": sent_s,
        }))
    session.close()


if __name__ == "__main__":
    main()
