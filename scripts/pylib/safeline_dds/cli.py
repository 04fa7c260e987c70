# SPDX-License-Identifier: Apache-2.0
"""scripts/safeline-dds: watch and operate a SafeLine network through its DDS bridge."""

import argparse
import json
import os
import signal
import sys
import time

from . import config
from . import types as T
from . import values as V

EXIT_OK, EXIT_FAILED, EXIT_USAGE, EXIT_NO_BRIDGE, EXIT_TIMEOUT = 0, 1, 2, 3, 4

NMT_NAMES = {0: "BOOT-UP", 4: "STOPPED", 5: "OPERATIONAL", 127: "PRE-OPERATIONAL",
             T.NMT_UNKNOWN: "?"}
HB_NAMES = {T.HB_NONE: "-", T.HB_WAITING: "waiting", T.HB_ACTIVE: "ok", T.HB_LOST: "LOST"}
CAN_STATES = {0: "error-active", 1: "error-warning", 2: "error-passive", 3: "bus-off",
              4: "stopped", 255: "?"}
STALE_S = 3.0

USAGE_EPILOG = """\
commands:
  watch                      live table of lines and nodes, refreshed in place
  nodes | lines | emcy [NODE] | values
                             the current state (emcy: the recent emergencies)
  read NODE INDEX SUB        SDO upload, decoded with the node's EDS
  write NODE INDEX SUB VALUE SDO download, typed from the node's EDS (or --type)
  info NODE INDEX SUB        data type, access and name from the node's EDS
  nmt start|stop|preop|reset|reset-comm NODE|all

INDEX and SUB are hex (1017, 0x1017 or 1017h); NODE is 1..127.
exit status: 0 ok, 1 request refused or failed, 2 usage, 3 no bridge found, 4 timeout.
Every participant runs on the loopback configuration unless --dds-config names another.
"""


class Failure(Exception):
    def __init__(self, message, code=EXIT_FAILED, status=None, details=None):
        super().__init__(message)
        self.code = code
        self.status = status
        self.details = details or {}


# --- arguments ----------------------------------------------------------------------------------

def hex_arg(text, limit, what):
    t = text.strip().lower()
    if t.startswith("0x"):
        t = t[2:]
    elif t.endswith("h"):
        t = t[:-1]
    try:
        v = int(t, 16)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{what} '{text}': hex, e.g. 1017 or 0x1017")
    if not 0 <= v <= limit:
        raise argparse.ArgumentTypeError(f"{what} '{text}': 0..{limit:X}h")
    return v


def node_arg(text):
    try:
        v = int(text, 0)
    except ValueError:
        raise argparse.ArgumentTypeError(f"node '{text}': a number 1..127")
    if not 1 <= v <= 127:
        raise argparse.ArgumentTypeError(f"node '{text}': 1..127")
    return v


def nmt_node_arg(text):
    return 0 if text == "all" else node_arg(text)


def build_parser():
    p = argparse.ArgumentParser(
        prog="safeline-dds", formatter_class=argparse.RawDescriptionHelpFormatter,
        description="Watch and operate a SafeLine CANopen network through its DDS bridge.",
        epilog=USAGE_EPILOG)
    p.add_argument("--domain", type=int, default=int(os.environ.get("SAFELINE_DDS_DOMAIN",
                                                                     config.DEFAULT_DOMAIN)),
                   help="DDS domain (default 42, or $SAFELINE_DDS_DOMAIN)")
    p.add_argument("--dds-config", metavar="FILE",
                   help="your own Cyclone DDS configuration instead of the loopback one")
    p.add_argument("--bridge", metavar="NAME", help="the bridge to use when there are several")
    p.add_argument("--client", metavar="NAME",
                   help="client name the allow-list matches (default $SAFELINE_DDS_CLIENT "
                        "or $USER)")
    p.add_argument("--line", type=int, default=0, help="CAN line of the node (default 0)")
    p.add_argument("--timeout", type=float, default=5.0,
                   help="seconds to find the bridge, and for each request (default 5)")
    p.add_argument("--json", action="store_true", help="JSON output for scripts")
    sub = p.add_subparsers(dest="cmd", metavar="COMMAND")
    sub.required = True

    w = sub.add_parser("watch", help="live table of lines and nodes")
    w.add_argument("--interval", type=float, default=0.5, help="refresh period [s]")
    w.add_argument("--count", type=int, default=0,
                   help="stop after this many refreshes (default: until Ctrl-C)")
    sub.add_parser("nodes", help="nodes and their state")
    sub.add_parser("lines", help="lines and their counters")
    e = sub.add_parser("emcy", help="recent emergencies (16 per producer)")
    e.add_argument("node", nargs="?", type=node_arg)
    sub.add_parser("values", help="object values the bridge publishes")

    def transfer_opts(sp):
        g = sp.add_mutually_exclusive_group()
        g.add_argument("--block", action="store_const", dest="mode", const=T.MODE_BLOCK,
                       help="SDO block transfer")
        g.add_argument("--segmented", action="store_const", dest="mode",
                       const=T.MODE_SEGMENTED, help="SDO segmented transfer")
        sp.set_defaults(mode=T.MODE_AUTO)

    r = sub.add_parser("read", help="SDO upload")
    r.add_argument("node", type=node_arg)
    r.add_argument("index", type=lambda s: hex_arg(s, 0xFFFF, "index"))
    r.add_argument("sub", type=lambda s: hex_arg(s, 0xFF, "sub-index"))
    r.add_argument("--type", dest="dtype", help="decode as this type instead of the EDS's")
    r.add_argument("--out", metavar="FILE", help="write the raw value into FILE")
    transfer_opts(r)
    wr = sub.add_parser("write", help="SDO download")
    wr.add_argument("node", type=node_arg)
    wr.add_argument("index", type=lambda s: hex_arg(s, 0xFFFF, "index"))
    wr.add_argument("sub", type=lambda s: hex_arg(s, 0xFF, "sub-index"))
    wr.add_argument("value", nargs="?")
    wr.add_argument("--type", dest="dtype", help="type the value as this (u16, i32, string...)")
    wr.add_argument("--file", metavar="FILE", help="write the bytes of FILE")
    transfer_opts(wr)
    i = sub.add_parser("info", help="what the node's EDS says of an object")
    i.add_argument("node", type=node_arg)
    i.add_argument("index", type=lambda s: hex_arg(s, 0xFFFF, "index"))
    i.add_argument("sub", type=lambda s: hex_arg(s, 0xFF, "sub-index"))
    n = sub.add_parser("nmt", help="NMT command")
    n.add_argument("command", choices=["start", "stop", "preop", "reset", "reset-comm"])
    n.add_argument("node", type=nmt_node_arg, help="1..127 or all")
    return p


# --- formatting ---------------------------------------------------------------------------------

def age(now_ns, t_ns):
    if not t_ns:
        return None
    return max(0.0, (now_ns - t_ns) / 1e9)


def fmt_age(a):
    if a is None:
        return "-"
    if a < 60:
        return f"{a:.1f}s"
    if a < 3600:
        return f"{a / 60:.1f}min"
    return f"{a / 3600:.1f}h"


def obj_name(index, sub):
    return f"{index:04X}:{sub:02X}"


def boot_text(status):
    if status == T.BOOT_NONE:
        return "-"
    return "OK" if status == 0 else chr(status)


def node_dict(n, alive, now_ns, last_emcy=None, srdos=()):
    d = {
        "line": n.line, "node": n.node_id, "name": n.name, "alive": alive, "local": n.local,
        "nmt_state": n.nmt_state, "nmt": NMT_NAMES.get(n.nmt_state, f"{n.nmt_state:#04x}"),
        "heartbeat": HB_NAMES.get(n.heartbeat, "?"),
        "heartbeat_age_s": age(now_ns, n.heartbeat_ns),
        "guarding": HB_NAMES.get(n.guarding, "?"),
        "boot": boot_text(n.boot_status),
        "error_register": n.error_register, "emcy_count": n.emcy_count,
    }
    ident = {}
    for bit, field in enumerate(("device_type", "vendor_id", "product_code", "revision",
                                 "serial")):
        if n.identity_mask & (1 << bit):
            ident[field] = getattr(n, field)
    d["identity"] = ident
    d["last_emcy"] = emcy_dict(last_emcy, now_ns) if last_emcy is not None else None
    d["srdo"] = [{"srdo": s.srdo, "safe": s.safe, "reason": s.reason_text} for s in srdos]
    d["safe_state"] = any(s.safe for s in srdos)
    return d


def emcy_dict(e, now_ns):
    return {"line": e.line, "node": e.node_id, "code": e.code, "code_hex": f"{e.code:04X}",
            "error_register": e.error_register, "msef": list(e.msef), "own": e.own,
            "cob_id": e.cob_id, "seq": e.seq, "age_s": age(now_ns, e.time_ns)}


def snapshot(client):
    """Everything the client knows now, as plain data (the base of watch, nodes, --json)."""
    now = time.time_ns()
    bridges = client._latest(T.TOPIC_BRIDGE, lambda s: s.bridge)
    lines = client.line_states()
    nodes = client.node_states()
    last = {}
    for e in client.emcys():
        last[(e.line, e.node_id)] = e
    srdos = {}
    for (line, node, _), (s, _) in sorted(client.srdos().items()):
        srdos.setdefault((line, node), []).append(s)
    out = {"time_ns": now, "bridges": [], "lines": [], "nodes": []}
    for name, (b, alive) in sorted(bridges.items()):
        seen = age(now, b.time_ns)
        out["bridges"].append({
            "bridge": b.bridge, "version": b.version, "domain": b.domain_id,
            "alive": alive and seen is not None and seen < STALE_S, "seen_s": seen,
            "uptime_s": age(b.time_ns, b.started_ns), "started_ns": b.started_ns,
            "read_only": b.read_only, "events": b.events, "events_lost": b.events_lost,
            "queue_max": b.queue_max, "queue_size": b.queue_size, "samples": b.samples,
            "requests": b.requests, "refused": b.refused, "malformed": b.malformed})
    for line, (s, alive) in sorted(lines.items()):
        out["lines"].append({
            "line": s.line, "name": s.name, "alive": alive,
            "can_state": CAN_STATES.get(s.can_state, str(s.can_state)),
            "tx_err_cnt": s.tx_err_cnt, "rx_err_cnt": s.rx_err_cnt,
            "active_line": s.active_line, "rx_frames": s.rx_frames, "tx_frames": s.tx_frames,
            "rx_overruns": s.rx_overruns, "tx_dropped": s.tx_dropped, "tx_errors": s.tx_errors,
            "events_lost": s.events_lost, "nodes": s.nodes})
    for key, (n, alive) in sorted(nodes.items()):
        out["nodes"].append(node_dict(n, alive, now, last.get(key), srdos.get(key, ())))
    return out


def emcy_text(e):
    if e is None:
        return "-"
    return f"{e['code_hex']}h {fmt_age(e['age_s'])} ago"


def table(snap, domain):
    rows = []
    if not snap["bridges"]:
        rows.append(f"waiting for a bridge on DDS domain {domain} ...")
    for b in snap["bridges"]:
        state = "up" if b["alive"] else f"LOST (last seen {fmt_age(b['seen_s'])} ago)"
        rows.append(f"bridge {b['bridge']} ({b['version']}, domain {b['domain']}): {state}, "
                    f"up {fmt_age(b['uptime_s'])}, events {b['events']} "
                    f"(lost {b['events_lost']}), requests {b['requests']} "
                    f"(refused {b['refused']}), {'read-only' if b['read_only'] else 'allow-list'}")
    for ln in snap["lines"]:
        rows.append(f"line {ln['line']} {ln['name']}: {ln['can_state']} "
                    f"(tec {ln['tx_err_cnt']} rec {ln['rx_err_cnt']}), rx {ln['rx_frames']} "
                    f"tx {ln['tx_frames']}, overruns {ln['rx_overruns']}, "
                    f"events lost {ln['events_lost']}"
                    + ("" if ln["alive"] else "  [stale]"))
    rows.append("")
    rows.append(f"{'LINE':>4} {'NODE':>4}  {'NAME':<12} {'NMT':<16} {'HEARTBEAT':<13} "
                f"{'BOOT':<4}  {'LAST EMCY':<16} {'SAFE STATE':<12} ERR")
    for n in snap["nodes"]:
        if n["local"]:
            hb = "local"
        elif n["heartbeat"] == "-":
            hb = f"seen {fmt_age(n['heartbeat_age_s'])}" if n["heartbeat_age_s"] is not None \
                else "-"
        else:
            hb = f"{n['heartbeat']} {fmt_age(n['heartbeat_age_s'])}" \
                if n["heartbeat_age_s"] is not None else n["heartbeat"]
        if n["srdo"]:
            unsafe = [s for s in n["srdo"] if s["safe"]]
            safe = (f"SAFE {unsafe[0]['srdo']}:{unsafe[0]['reason']}" if unsafe
                    else "valid")
        else:
            safe = "-"
        nmt = n["nmt"] + ("" if n["alive"] else " ?")
        rows.append(f"{n['line']:>4} {n['node']:>4}  {n['name'][:12]:<12} {nmt:<16} "
                    f"{hb:<13} {n['boot']:<4}  {emcy_text(n['last_emcy']):<16} "
                    f"{safe[:12]:<12} {n['error_register']:02X}h")
    return "\n".join(rows)


# --- commands -----------------------------------------------------------------------------------

def out(args, data, text):
    if args.json:
        print(json.dumps(data, sort_keys=True))
    else:
        print(text)


def cmd_watch(client, args):
    tty = sys.stdout.isatty() and not args.json
    client.open_state()
    n = 0
    if tty:
        sys.stdout.write("\x1b[?25l\x1b[H\x1b[2J")
    try:
        while True:
            snap = snapshot(client)
            if args.json:
                print(json.dumps(snap, sort_keys=True), flush=True)
            elif tty:
                sys.stdout.write("\x1b[H" + table(snap, client.domain_id).replace(
                    "\n", "\x1b[K\n") + "\x1b[K\n\x1b[J")
                sys.stdout.flush()
            else:
                print(table(snap, client.domain_id) + "\n", flush=True)
            n += 1
            if args.count and n >= args.count:
                break
            time.sleep(args.interval)
    except KeyboardInterrupt:
        pass
    finally:
        if tty:
            sys.stdout.write("\x1b[?25h")
            sys.stdout.flush()
    return EXIT_OK


def wait_state(client, args):
    client.open_state()
    client.wait_bridge(args.timeout)
    # The history of the state readers arrives right after the bridge's.
    time.sleep(0.2)


def cmd_nodes(client, args):
    wait_state(client, args)
    snap = snapshot(client)
    out(args, snap["nodes"], table(snap, client.domain_id))
    return EXIT_OK


def cmd_lines(client, args):
    wait_state(client, args)
    snap = snapshot(client)
    text = "\n".join(
        f"line {ln['line']} {ln['name']}: {ln['can_state']}, rx {ln['rx_frames']} "
        f"tx {ln['tx_frames']}, overruns {ln['rx_overruns']}, tx dropped {ln['tx_dropped']}, "
        f"tx errors {ln['tx_errors']}, events lost {ln['events_lost']}, "
        f"{ln['nodes']} bridged node(s)" for ln in snap["lines"]) or "no lines"
    out(args, snap["lines"], text)
    return EXIT_OK


def cmd_emcy(client, args):
    wait_state(client, args)
    now = time.time_ns()
    items = [emcy_dict(e, now) for e in client.emcys()
             if args.node is None or e.node_id == args.node]
    text = "\n".join(
        f"line {e['line']} node {e['node']:>3}  {e['code_hex']}h  reg {e['error_register']:02X}h"
        f"  msef {' '.join(f'{b:02x}' for b in e['msef'])}  #{e['seq']}  "
        f"{'sent' if e['own'] else 'received'}  {fmt_age(e['age_s'])} ago"
        for e in items) or "no emergencies"
    out(args, items, text)
    return EXIT_OK


def cmd_values(client, args):
    wait_state(client, args)
    items = []
    for _, (v, alive) in sorted(client.values().items()):
        value, vtext = V.decode(v.data, v.data_type) if not v.abort_code else (None, None)
        items.append({"line": v.line, "node": v.node_id, "index": f"{v.index:04X}",
                      "sub": f"{v.subindex:02X}", "type": V.type_name(v.data_type),
                      "value": value, "text": vtext, "abort_code": v.abort_code,
                      "size": v.size, "changes": v.changes, "alive": alive})
    text = "\n".join(
        f"line {i['line']} node {i['node']:>3} {i['index']}:{i['sub']}  "
        + (f"{i['text']} ({i['type']})" if i["abort_code"] == 0 else
           f"abort {i['abort_code']:08X}h ({V.abort_text(i['abort_code'])})")
        + f"  changes {i['changes']}" for i in items) or "no values"
    out(args, items, text)
    return EXIT_OK


def check_reply(rep, what):
    if rep.status == T.STATUS_OK:
        return
    status = T.STATUS_NAMES.get(rep.status, str(rep.status))
    details = {"status": status}
    if rep.status == T.STATUS_ABORTED:
        details["abort_code"] = rep.abort_code
        details["abort_text"] = V.abort_text(rep.abort_code)
    raise Failure(f"{what}: {status}: {rep.message}",
                  EXIT_TIMEOUT if rep.status == T.STATUS_TIMEOUT else EXIT_FAILED,
                  status, details)


def cmd_info(client, args):
    rep = client.sdo_info(args.node, args.index, args.sub, line=args.line,
                          timeout=args.timeout, discovery=args.timeout)
    what = f"node {args.node} {obj_name(args.index, args.sub)}"
    check_reply(rep, what)
    data = {"node": args.node, "index": f"{args.index:04X}", "sub": f"{args.sub:02X}",
            "name": rep.name, "type": V.type_name(rep.data_type), "data_type": rep.data_type,
            "access": V.ACCESS.get(rep.access, "?")}
    out(args, data, f"{what} {rep.name}: {data['type']}, {data['access']}")
    return EXIT_OK


def cmd_read(client, args):
    what = f"node {args.node} {obj_name(args.index, args.sub)}"
    rep = client.sdo_read(args.node, args.index, args.sub, line=args.line, mode=args.mode,
                          timeout_ms=int(args.timeout * 1000), timeout=args.timeout + 2,
                          discovery=args.timeout)
    check_reply(rep, what)
    raw = bytes(rep.data)
    dtype = V.parse_type(args.dtype) if args.dtype else rep.data_type
    value, text = V.decode(raw, dtype)
    if args.out:
        with open(args.out, "wb") as f:
            f.write(raw)
    data = {"node": args.node, "index": f"{args.index:04X}", "sub": f"{args.sub:02X}",
            "name": rep.name, "type": V.type_name(dtype), "value": value, "size": len(raw),
            "hex": raw.hex() if len(raw) <= 4096 else None}
    label = f" {rep.name}" if rep.name else ""
    out(args, data, f"{what}{label} = {text} ({V.type_name(dtype)}, {len(raw)} bytes)")
    return EXIT_OK


def cmd_write(client, args):
    what = f"node {args.node} {obj_name(args.index, args.sub)}"
    if (args.value is None) == (args.file is None):
        raise Failure("write: give a VALUE or --file FILE", EXIT_USAGE)
    name = ""
    if args.file:
        with open(args.file, "rb") as f:
            raw = f.read()
        dtype = V.DOMAIN
    else:
        if args.dtype:
            dtype = V.parse_type(args.dtype)
        else:
            info = client.sdo_info(args.node, args.index, args.sub, line=args.line,
                                   timeout=args.timeout, discovery=args.timeout)
            if info.status != T.STATUS_OK:
                raise Failure(f"{what}: no type for the value ({info.message}); "
                              "give --type", EXIT_FAILED, T.STATUS_NAMES.get(info.status))
            dtype, name = info.data_type, info.name
        try:
            raw = V.encode(args.value, dtype)
        except ValueError as e:
            raise Failure(f"{what}: {e}", EXIT_USAGE)
    rep = client.sdo_write(args.node, args.index, args.sub, raw, line=args.line,
                           mode=args.mode, timeout_ms=int(args.timeout * 1000),
                           timeout=args.timeout + 2, discovery=args.timeout)
    check_reply(rep, what)
    shown = args.value if args.value is not None else f"{len(raw)} bytes of {args.file}"
    data = {"node": args.node, "index": f"{args.index:04X}", "sub": f"{args.sub:02X}",
            "name": name, "type": V.type_name(dtype), "size": len(raw), "status": "ok"}
    label = f" {name}" if name else ""
    out(args, data, f"{what}{label} := {shown} ({V.type_name(dtype)}, {len(raw)} bytes): ok")
    return EXIT_OK


def cmd_nmt(client, args):
    from .client import NMT_COMMANDS

    target = "all nodes" if args.node == 0 else f"node {args.node}"
    rep = client.nmt(args.node, NMT_COMMANDS[args.command], line=args.line,
                     timeout=args.timeout, discovery=args.timeout)
    check_reply(rep, f"nmt {args.command} {target}")
    data = {"command": args.command, "node": args.node, "status": "ok",
            "message": rep.message}
    out(args, data, f"nmt {args.command} {target}: {rep.message}")
    return EXIT_OK


COMMANDS = {"watch": cmd_watch, "nodes": cmd_nodes, "lines": cmd_lines, "emcy": cmd_emcy,
            "values": cmd_values, "read": cmd_read, "write": cmd_write, "info": cmd_info,
            "nmt": cmd_nmt}


def main(argv=None):
    args = build_parser().parse_args(argv)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(EXIT_OK))
    try:
        from .client import BridgeClient, NoBridge, RequestTimeout
    except ImportError as e:
        print(f"safeline-dds: {e} (the Python binding: pip install cyclonedds==11.0.1, "
              "scripts/setup installs it)", file=sys.stderr)
        return EXIT_FAILED
    client = None
    try:
        client = BridgeClient(args.domain, args.dds_config, args.client, args.bridge)
        return COMMANDS[args.cmd](client, args)
    except config.ConfigError as e:
        return fail(args, str(e), EXIT_USAGE, "config")
    except NoBridge as e:
        return fail(args, str(e), EXIT_NO_BRIDGE, "no bridge")
    except RequestTimeout as e:
        return fail(args, str(e), EXIT_TIMEOUT, "timeout")
    except Failure as e:
        return fail(args, str(e), e.code, e.status, e.details)
    except ValueError as e:
        return fail(args, str(e), EXIT_USAGE, "usage")
    except OSError as e:
        return fail(args, str(e), EXIT_FAILED, "error")
    finally:
        # The participant's goodbye reaches the bridge now, not at its lease's end.
        if client is not None:
            client.close()


def run(argv=None):
    """The command line's entry: main(), then out without the interpreter's finalization.

    After SIGINT under load `watch` took seconds to exit, none of it in a wait: main()
    returned within milliseconds and deleting the participant took 0.2-0.5 s, but Python's
    finalization of the DDS binding's modules and objects took 1.5 s at a load of 19 on two
    cores (more on a busier machine). Nothing is left for it to do once the participant is
    gone, so the streams are flushed and the process ends with os._exit().
    """
    try:
        code = main(argv)
    except SystemExit as e:  # argparse's --help and usage errors, SIGTERM
        code = e.code
    if code is None:
        code = EXIT_OK
    elif not isinstance(code, int):
        print(code, file=sys.stderr)
        code = EXIT_FAILED
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a reader that went away, a closed stream
            pass
    os._exit(code)


def fail(args, message, code, status, details=None):
    if args.json:
        print(json.dumps(dict({"error": message, "status": status}, **(details or {})),
                         sort_keys=True))
    print(f"safeline-dds: error: {message}", file=sys.stderr)
    return code
