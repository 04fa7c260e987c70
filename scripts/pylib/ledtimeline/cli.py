# SPDX-License-Identifier: Apache-2.0
"""scripts/led-timeline LOG [-o PICTURE.png] [--min-agreement PERCENT]

Reads the TRACE lines of a run (samples/canopen/indicators prints them at its end), draws
each node's RUN and ERR LED as recorded, with the waveform its patterns call for drawn beside
it, and prints how often the two agree. Exit status: 0, 1 when the agreement is below
--min-agreement, 2 for bad usage or an unreadable trace.
"""

import argparse
import sys

from .trace import TraceError, agreement, expected, parse, recorded

COLOURS = {0: ("RUN", "tab:green"), 1: ("ERR", "tab:red")}


def draw(nodes, out, step_us=5_000):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ids = sorted(nodes)
    t0 = min(n.patterns[0][0] for n in nodes.values() if n.patterns)
    t1 = max(max([n.patterns[-1][0]] + [c[-1][0] for c in n.changes.values() if c])
             for n in nodes.values() if n.patterns)
    fig, axes = plt.subplots(len(ids), 1, figsize=(14, 1.9 * len(ids)), sharex=True,
                             squeeze=False)
    times = list(range(t0, t1, step_us))
    xs = [(t - t0) / 1e6 for t in times]
    for ax, node_id in zip(axes[:, 0], ids):
        node = nodes[node_id]
        rows = []
        for colour in (1, 0):
            name, c = COLOURS[colour]
            base = 3.0 * (1 - colour)  # red on top
            rec = [base + 1.2 * recorded(node, t, colour) for t in times]
            exp = [base + 1.4 + 1.2 * bool(expected(node, t, colour)) for t in times]
            ax.step(xs, rec, where="post", color=c, linewidth=1.4)
            ax.step(xs, exp, where="post", color=c, linewidth=0.9, linestyle=":")
            rows += [(base + 0.6, f"{name}"), (base + 2.0, f"{name} expected")]
        for t, run, err in node.patterns:
            x = (t - t0) / 1e6
            ax.axvline(x, color="0.75", linewidth=0.6)
            ax.text(x + 0.02, 5.9, f"{run} / {err}", fontsize=7, color="0.3", va="top")
        good, total = agreement(node)
        share = 100.0 * good / total if total else 0.0
        ax.set_yticks([r[0] for r in rows], [r[1] for r in rows], fontsize=7)
        ax.set_ylim(-0.3, 6.1)
        ax.set_ylabel(f"node {node_id}\n{share:.1f} %", rotation=0, ha="right", va="center")
        ax.grid(axis="x", linewidth=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    fig.suptitle("CiA 303-3 indicators: recorded (solid) and expected (dotted)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="led-timeline", description=__doc__.splitlines()[0])
    ap.add_argument("log", help="console output of a run with TRACE lines ('-' for stdin)")
    ap.add_argument("-o", "--output", help="PNG to write (default: no picture)")
    ap.add_argument("--min-agreement", type=float, default=None, metavar="PERCENT",
                    help="exit 1 if a node's LEDs agree with their patterns less often")
    args = ap.parse_args(argv)
    if args.min_agreement is not None and not 0.0 <= args.min_agreement <= 100.0:
        ap.error("--min-agreement must be 0..100")
    try:
        if args.log == "-":
            lines, source = sys.stdin.read().splitlines(), "<stdin>"
        else:
            with open(args.log, encoding="utf-8", errors="replace") as f:
                lines, source = f.read().splitlines(), args.log
        nodes = parse(lines, source)
    except (OSError, TraceError) as e:
        print(f"led-timeline: {e}", file=sys.stderr)
        return 2
    worst = 100.0
    for node_id in sorted(nodes):
        good, total = agreement(nodes[node_id])
        share = 100.0 * good / total if total else 0.0
        worst = min(worst, share)
        print(f"node {node_id}: {good}/{total} samples agree ({share:.2f} %)")
    if args.output:
        draw(nodes, args.output)
        print(f"wrote {args.output}")
    if args.min_agreement is not None and worst < args.min_agreement:
        print(f"led-timeline: agreement {worst:.2f} % below {args.min_agreement} %",
              file=sys.stderr)
        return 1
    return 0
