#!/usr/bin/env python3
"""A command flood against a tandem cell, with nothing but the eclipse-zenoh package.

One sender (`flood`) sends --flood commands spread over --seconds while another (`operator`)
sends --operator commands over the same time, each a Zenoh query to tandem/<cell>/<key>/cmd
with the attachment `sender=<name>`. Prints one JSON summary on stdout: per sender the replies
by outcome and the queries that got no reply.

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

    def handler(sender):
        def on_reply(reply):
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
        return on_reply

    def send(sender):
        session.get(key, handler(sender), payload=a.text, attachment=f"sender={sender}", timeout=a.wait)

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
    with lock:
        print(json.dumps({
            "flood": outcomes["flood"],
            "operator": outcomes["operator"],
            "missing": {"flood": a.flood - replied["flood"], "operator": a.operator - replied["operator"]},
            "probe": outcomes["probe"],
            "sent_s": sent_s,
        }))
    session.close()


if __name__ == "__main__":
    main()
