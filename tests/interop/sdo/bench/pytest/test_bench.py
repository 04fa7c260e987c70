# SPDX-License-Identifier: Apache-2.0
"""SDO block transfer on a real vcan with python-canopen as the peer.

python-canopen's SdoClient downloads 100 000 bytes into hello_node's DOMAIN 2100h with the
block protocol (CRC on; the server offers blksize 127) and uploads them again, ROUNDS times
each way. Per direction: payload bytes/s of the best and the median round (time from opening
the stream to its close, which waits for the server's end response), every round's time, the
server's frames in the best round (python-can does not hand the client its own frames), and
what python-canopen reported: sends the socket refused (retried after its RETRY_DELAY) and
sub-blocks the server acknowledged in part (sent again). A segmented transfer of 10 000
bytes each way is the reference (one round trip per 7 bytes).

Our SDO client against python-canopen is not measured: python-canopen's SdoServer (2.4)
serves expedited and segmented transfers only (it aborts a block download and answers a
block upload with a segmented one).

Figures are printed as BENCH lines and kept in bench-sdo-vcan.json of the build folder.
Inside the VM system calls cost far more than on the host, so these figures say what the
pair reaches there, not what the stack reaches on a controller.
"""

import json
import logging
import os
import statistics
import time

import can

from conftest import NODE_ID

DATA = 0x2100  # DOMAIN, up to 128 KiB, provider-backed
SIZE = 100_000
SEG_SIZE = 10_000
ROUNDS = 3
SDO_TX = 0x580 + NODE_ID


def payload(n, seed):
    # Pseudo-random bytes: a run of equal bytes would not show the CRC or stuffing cost.
    x = seed * 2654435761 & 0xFFFFFFFF or 1
    out = bytearray(n)
    for i in range(n):
        x ^= (x << 13) & 0xFFFFFFFF
        x ^= x >> 17
        x ^= (x << 5) & 0xFFFFFFFF
        out[i] = x & 0xFF
    return bytes(out)


class Counter(can.Listener):
    """Counts the server's SDO frames (python-can does not hand us our own)."""

    def __init__(self):
        self.n = 0

    def on_message_received(self, msg):
        if msg.arbitration_id == SDO_TX:
            self.n += 1


class Hitches(logging.Handler):
    """What python-canopen's client reports: a send the socket refused (retried after
    RETRY_DELAY) and a sub-block the server acknowledged only in part (sent again)."""

    def __init__(self):
        super().__init__(logging.INFO)
        self.send_retries = 0
        self.resent_blocks = 0

    def emit(self, record):
        if record.funcName == "send_request":
            self.send_retries += 1
        elif "sequences were received" in record.getMessage():
            self.resent_blocks += 1


def block_download(node, data):
    with node.sdo.open(DATA, 0, "wb", size=len(data), block_transfer=True,
                       request_crc_support=True) as f:
        f.write(data)


def block_upload(node):
    with node.sdo.open(DATA, 0, "rb", block_transfer=True, request_crc_support=True) as f:
        return f.read()


def timed(counter, hitches, fn, *args):
    n0, s0, r0 = counter.n, hitches.send_retries, hitches.resent_blocks
    t0 = time.perf_counter()
    result = fn(*args)
    dt = time.perf_counter() - t0
    return dt, {"server_frames": counter.n - n0, "send_retries": hitches.send_retries - s0,
                "resent_subblocks": hitches.resent_blocks - r0}, result


def figure(name, size, rounds, counts, **extra):
    """rounds: seconds per round; counts: per round, what timed() counted."""
    best = min(range(len(rounds)), key=rounds.__getitem__)
    fig = {"name": name, "bytes": size, "rounds": len(rounds),
           "bytes_per_s": round(size / rounds[best]), "ms": round(rounds[best] * 1000, 1),
           "median_bytes_per_s": round(size / statistics.median(rounds)),
           "round_ms": [round(r * 1000, 1) for r in rounds],
           "peer": f"python-canopen {canopen_version()}"}
    fig.update(counts[best])
    for key in ("send_retries", "resent_subblocks"):
        fig[key + "_all_rounds"] = sum(c[key] for c in counts)
    fig.update(extra)
    print("BENCH " + json.dumps(fig, sort_keys=True), flush=True)
    return fig


def canopen_version():
    import canopen
    return canopen.__version__


def test_sdo_block_transfer_rates(dut, network):
    counter = Counter()
    hitches = Hitches()
    client_log = logging.getLogger("canopen.sdo.client")
    level = client_log.level
    client_log.setLevel(logging.INFO)
    client_log.addHandler(hitches)
    network.notifier.add_listener(counter)
    results = []
    try:
        down, up, down_counts, up_counts = [], [], [], []
        for r in range(ROUNDS):
            data = payload(SIZE, seed=r + 1)
            dt, counts, _ = timed(counter, hitches, block_download, dut, data)
            down.append(dt)
            down_counts.append(counts)
            dt, counts, back = timed(counter, hitches, block_upload, dut)
            assert back == data, f"round {r}: the upload differs from the download"
            up.append(dt)
            up_counts.append(counts)
        results.append(figure("sdo.vcan_block_download_100kB", SIZE, down, down_counts,
                              crc=True))
        results.append(figure("sdo.vcan_block_upload_100kB", SIZE, up, up_counts, crc=True))

        data = payload(SEG_SIZE, seed=99)
        dt, counts, _ = timed(counter, hitches, dut.sdo.download, DATA, 0, data, True)
        results.append(figure("sdo.vcan_segmented_download_10kB", SEG_SIZE, [dt], [counts]))
        dt, counts, back = timed(counter, hitches, dut.sdo.upload, DATA, 0)
        assert back == data
        results.append(figure("sdo.vcan_segmented_upload_10kB", SEG_SIZE, [dt], [counts]))
    finally:
        network.notifier.remove_listener(counter)
        client_log.removeHandler(hitches)
        client_log.setLevel(level)
        out = os.path.join(os.environ.get("SAFELINE_BUILD_DIR", "."), "bench-sdo-vcan.json")
        with open(out, "w") as f:
            json.dump({"figures": results}, f, indent=1)
