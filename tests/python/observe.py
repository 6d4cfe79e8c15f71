#!/usr/bin/env python3
"""A tandem cell seen from Python, with nothing but the eclipse-zenoh package.

Subscribes to everything of a cell (tandem/<cell>/**), sends commands as Zenoh queries to
tandem/<cell>/<node>/<object>/cmd (or .../cmd/<sender> with --sender), asks which hosts are alive (liveliness), and prints one JSON
summary on stdout: the keys seen and how often, the last state of every axis, the replies, the
gateways' `command` events (who commanded what), and every edge of the nodes' signals (tandem/<cell>/<node>/<signal>/signal), in arrival order.

  observe.py --cell line --connect tcp/10.0.0.1:7447 --seconds 4 \
      --command followers/feed "MC_Power" --command followers/feed "MC_MoveVelocity --velocity 50"

A cell with [security] mode = "mtls" (docs/security.md) takes TLS endpoints and the client's
certificate from `tandem certs`: --ca pki/ca.pem --cert pki/observer-hmi.pem --key
pki/observer-hmi.key (or TANDEM_CA, TANDEM_CERT, TANDEM_KEY). With --ca alone the client dials
without a certificate (what an outsider does: the gateways refuse it). With a certificate it
subscribes to the observable keys one by one (the access control refuses `tandem/<cell>/**` as
a whole); --subscribe KEY replaces them.
"""
import argparse
import json
import os
import sys
import threading
import time

import zenoh


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cell", required=True)
    ap.add_argument("--connect", action="append", default=[], help="a gateway's endpoint")
    ap.add_argument("--seconds", type=float, default=3.0, help="how long to watch")
    ap.add_argument("--command", nargs=2, action="append", default=[], metavar=("NODE/OBJECT", "TEXT"))
    ap.add_argument("--garbage", action="append", default=[], metavar="KEY",
                    help="put a malformed payload on this key first (the gateways must drop and count it)")
    ap.add_argument("--ca", default=os.environ.get("TANDEM_CA"), help="the cell CA's certificate (mTLS)")
    ap.add_argument("--cert", default=os.environ.get("TANDEM_CERT"), help="an operator's or observer's certificate")
    ap.add_argument("--key", default=os.environ.get("TANDEM_KEY"), help="its private key")
    ap.add_argument("--sender", help="query tandem/<cell>/<node>/<object>/cmd/SENDER (the key an mTLS "
                    "cell serves: SENDER must be the certificate's CN); without, the key without a sender (plain cells)")
    ap.add_argument("--subscribe", action="append", default=[], metavar="KEY",
                    help="subscribe to this key expression (repeatable) instead of the default")
    ap.add_argument("--forge-state", action="append", default=[], metavar="KEY",
                    help="put a forged axis state (standing still, marked \"forged\": true) on KEY every 50 ms while watching")
    ap.add_argument("--forge-alive", action="append", default=[], metavar="HOST",
                    help="declare the liveliness token of a host that does not exist: tandem/<cell>/alive/HOST")
    ap.add_argument("--forge-clock", action="append", default=[], metavar="HOST",
                    help="answer the gateways' clock queries for HOST with a time an hour off")
    a = ap.parse_args()

    conf = zenoh.Config()
    conf.insert_json5("mode", '"peer"')
    conf.insert_json5("listen/endpoints", "[]")
    if a.connect:
        conf.insert_json5("connect/endpoints", json.dumps(a.connect))
        conf.insert_json5("scouting/multicast/enabled", "false")
    if a.ca:
        conf.insert_json5("transport/link/protocols", json.dumps(["tls"]))
        conf.insert_json5("scouting/gossip/enabled", "false")
        conf.insert_json5("transport/link/tls/root_ca_certificate", json.dumps(a.ca))
        if a.cert and a.key:
            conf.insert_json5("transport/link/tls/enable_mtls", "true")
            conf.insert_json5("transport/link/tls/connect_certificate", json.dumps(a.cert))
            conf.insert_json5("transport/link/tls/connect_private_key", json.dumps(a.key))
    session = zenoh.open(conf)

    counts = {}
    last = {}
    signals = []
    command_events = []
    forged_seen = [0]
    lock = threading.Lock()

    def on_sample(sample):
        key = str(sample.key_expr)
        with lock:
            counts[key] = counts.get(key, 0) + 1
            if key.endswith("/state") or key.endswith("/health") or "/gateway/" in key:
                try:
                    last[key] = json.loads(sample.payload.to_string())
                except ValueError:
                    last[key] = {"malformed": True}
                if isinstance(last[key], dict) and last[key].get("forged"):
                    forged_seen[0] += 1
            elif key.endswith("/events"):
                try:
                    e = json.loads(sample.payload.to_string())
                except ValueError:
                    e = {}
                if isinstance(e, dict) and e.get("outcome") == "command":
                    command_events.append(e)
            elif key.endswith("/signal"):
                try:
                    signals.append(json.loads(sample.payload.to_string()))
                except ValueError:
                    signals.append({"malformed": True, "key": key})

    c = a.cell
    keys = a.subscribe or (
        [f"tandem/{c}/*/*/state", f"tandem/{c}/*/health", f"tandem/{c}/*/*/events",
         f"tandem/{c}/*/log", f"tandem/{c}/*/*/signal", f"tandem/{c}/gateway/*"]
        if a.cert else [f"tandem/{c}/**"])
    subs = [session.declare_subscriber(k, on_sample) for k in keys]
    t0 = time.monotonic()
    alive_events = []

    def on_alive(sample):
        kind = "gone" if sample.kind == zenoh.SampleKind.DELETE else "alive"
        with lock:
            alive_events.append([round(time.monotonic() - t0, 3), kind, str(sample.key_expr)])

    alive_sub = session.liveliness().declare_subscriber(f"tandem/{a.cell}/alive/*", on_alive, history=True)

    # Forgeries: what an attacker holding only this session would try (issue 12).
    tokens = [session.liveliness().declare_token(f"tandem/{a.cell}/alive/{h}") for h in a.forge_alive]

    def on_clock(query):
        # The gateways' clock reply: the time in ns as text (services/gateway, "Clock watch").
        query.reply(query.key_expr, str(time.time_ns() + 3_600_000_000_000))

    clocks = [session.declare_queryable(f"tandem/{a.cell}/clock/{h}", on_clock) for h in a.forge_clock]
    stop_forging = threading.Event()

    def forge_states():
        while not stop_forging.is_set():
            for key in a.forge_state:
                session.put(key, json.dumps({"state": "Standstill", "position": 0.0, "velocity": 0.0,
                                             "forged": True}))
            stop_forging.wait(0.05)

    forger = threading.Thread(target=forge_states)
    forger.start()
    for key in a.garbage:
        for payload in (b"", b"\x00garbage", bytes(range(64)) + b"!"):
            session.put(key, payload)
    time.sleep(min(1.5, a.seconds))

    replies = []
    for target, text in a.command:
        key = f"tandem/{a.cell}/{target}/cmd" + (f"/{a.sender}" if a.sender else "")
        got = None
        for reply in session.get(key, payload=text, timeout=10.0):
            if reply.ok is not None:
                got = json.loads(reply.ok.payload.to_string())
            else:
                got = {"outcome": "zenoh-error", "message": reply.err.payload.to_string()}
        replies.append({"target": target, "text": text, "reply": got})
        time.sleep(0.3)

    time.sleep(max(0.0, a.seconds - 1.5))
    alive = sorted(str(r.ok.key_expr) for r in session.liveliness().get(f"tandem/{a.cell}/alive/*", timeout=2.0) if r.ok is not None)
    stop_forging.set()
    forger.join()
    for t in tokens:
        t.undeclare()
    for q in clocks:
        q.undeclare()
    for sub in subs:
        sub.undeclare()
    alive_sub.undeclare()
    with lock:
        summary = {
            "keys": counts,
            "forged_states_seen": forged_seen[0],
            "states": {k: v for k, v in last.items() if k.endswith("/state")},
            "health": {k: v for k, v in last.items() if k.endswith("/health")},
            "gateways": {k: v for k, v in last.items() if "/gateway/" in k},
            "replies": replies,
            "alive": alive,
            "alive_events": alive_events,
            "signals": signals,
            "command_events": command_events,
        }
    session.close()
    json.dump(summary, sys.stdout)
    print()


if __name__ == "__main__":
    main()
