# SPDX-License-Identifier: Apache-2.0
"""DDS bridge benchmark: a busy line's EMCY frames to a supervisory client.

Device 7 sends EMCY frames (8F00h) at a given rate on line 0 of the test network, each with
the CLOCK_MONOTONIC microseconds of its sending in bytes 3..6 of the frame. The gateway's EMCY
consumer turns each into an event, the bridge into a sample of canopen/emcy, and a reader in
this process (another participant, over loopback) takes them. Per rate: frames sent, events
the bridge took and lost (its exact counters), samples the client got, and the latency from
the frame's send time to the sample in the client's hands.
"""

import json
import os
import re
import threading
import time

from cyclonedds.core import (InstanceState, Policy, Qos, ReadCondition, SampleState, ViewState,
                             WaitSet)
from cyclonedds.sub import DataReader
from cyclonedds.util import duration

from safeline_dds import types as T

RATES = [200, 1000, 2000, 5000, 10000, 20000, 30000, 40000, 50000]
# A rate is sustained when every frame went out on time, the bridge lost nothing, the client
# got every sample, and the client kept up (its p99 latency below this).
KEPT_UP_US = 50000
SECONDS = 2
CODE = 0x8F00


def stats(fw):
    n = len(re.findall(r"^stats ", fw.text(), re.M))
    fw.send("stats")
    words = re.findall(r"^stats (.*)$", fw.text(), re.M)[n].split()
    return {words[i]: int(words[i + 1]) for i in range(0, len(words), 2)}


class Receiver:
    """Takes every EMCY sample of device 7 and notes its latency."""

    def __init__(self, client):
        qos = Qos(Policy.Reliability.Reliable(duration(seconds=1)),
                  Policy.Durability.TransientLocal, Policy.History.KeepAll)
        self.rd = DataReader(client.dp, client.topic(T.TOPIC_EMCY), qos=qos)
        self.ws = WaitSet(client.dp)
        self.ws.attach(ReadCondition(self.rd, SampleState.Any | ViewState.Any |
                                     InstanceState.Any))
        self.lat_us = []
        self.count = 0
        self.stop = False
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()

    def run(self):
        while not self.stop:
            got = self.rd.take(N=4096)
            now = (time.monotonic_ns() // 1000) & 0xFFFFFFFF
            for s in got:
                if getattr(s, "code", None) != CODE or s.node_id != 7:
                    continue
                stamp = int.from_bytes(bytes(s.msef[:4]), "little")
                self.lat_us.append((now - stamp) & 0xFFFFFFFF)
                self.count += 1
            if not got:
                self.ws.wait(duration(milliseconds=100))

    def reset(self):
        self.lat_us = []
        self.count = 0


def pct(values, p):
    v = sorted(values)
    return v[min(len(v) - 1, int(len(v) * p / 100))] if v else None


def test_bench(firmware, client):
    fw = firmware(dds=False, stdin=True)
    fw.wait_log(r"^ready$")
    c = client("bench")
    c.open_state()
    c.wait_bridge(10)
    rx = Receiver(c)
    time.sleep(1.0)
    results = []
    for rate in RATES:
        rx.reset()
        s0 = stats(fw)
        fw.send(f"bench {rate} {SECONDS}", timeout=SECONDS * 10 + 30)
        sent = re.findall(r"^bench sent (\d+) refused (\d+) in (\d+) us$", fw.text(), re.M)[-1]
        s1 = stats(fw)
        # What is still on its way arrives within a second.
        end = time.monotonic() + 2
        while rx.count < int(sent[0]) and time.monotonic() < end:
            time.sleep(0.05)
        r = {
            "name": f"dds_bridge.emcy_{rate}_per_s",
            "rate": rate,
            "sent": int(sent[0]),
            "send_refused": int(sent[1]),
            "send_s": int(sent[2]) / 1e6,
            "achieved_per_s": round(int(sent[0]) / (int(sent[2]) / 1e6)),
            "bridge_events": s1["events"] - s0["events"],
            "bridge_lost": s1["lost"] - s0["lost"],
            "queue_max": s1["queue_max"],
            "client_received": rx.count,
            "latency_p50_us": pct(rx.lat_us, 50),
            "latency_p99_us": pct(rx.lat_us, 99),
            "latency_max_us": max(rx.lat_us) if rx.lat_us else None,
        }
        results.append(r)
        print("BENCH " + json.dumps(r, sort_keys=True), flush=True)
    rx.stop = True
    sustained = [r for r in results if r["send_refused"] == 0 and r["bridge_lost"] == 0
                 and r["bridge_events"] >= r["sent"] and r["client_received"] >= r["sent"]
                 and r["latency_p99_us"] is not None and r["latency_p99_us"] < KEPT_UP_US]
    best = max(sustained, key=lambda r: r["rate"]) if sustained else None
    summary = {"name": "dds_bridge.summary",
               "sustained_events_per_s": best["rate"] if best else 0,
               "max_events_per_s_taken": max(round(r["bridge_events"] / r["send_s"])
                                             for r in results),
               "bridge_lost_total": sum(r["bridge_lost"] for r in results),
               "latency_p50_us_at_200_per_s": results[0]["latency_p50_us"],
               "latency_p99_us_at_200_per_s": results[0]["latency_p99_us"]}
    print("BENCH " + json.dumps(summary, sort_keys=True), flush=True)
    out = os.path.join(os.environ.get("SAFELINE_BUILD_DIR", "."), "bench-dds.json")
    with open(out, "w") as f:
        json.dump(results + [summary], f, indent=1)
    assert results and results[0]["sent"] > 0 and results[0]["client_received"] > 0
