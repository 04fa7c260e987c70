#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Merge Kconfig fragments into .config and autoconf.h with kconfiglib.

Fragments are applied in the order given (later ones win). Like Zephyr's kconfig.py, the build
stops when a fragment assigns an undefined symbol, gives a malformed value, or assigns a value
that does not stick (a dependency is missing, a range excludes it, a choice overrides it).

When the fragments have not changed since the last run and a .config exists, that .config is
the starting point instead, so changes saved from menuconfig/guiconfig survive a rebuild.
"""

import argparse
import hashlib
import os
import sys

import kconfiglib


def fragments_digest(paths):
    h = hashlib.sha256()
    for p in paths:
        h.update(p.encode() + b"\0")
        with open(p, "rb") as f:
            h.update(f.read())
        h.update(b"\0")
    return h.hexdigest()


def user_assignments(kconf):
    """Symbols and choices that a fragment gave a value to."""
    return [s for s in kconf.unique_defined_syms if s.user_value is not None]


def value_did_not_stick(sym):
    if sym.choice is not None and sym.user_value == 2:
        # A later fragment picking another symbol of the same choice overrides this one, as
        # any later assignment does; only a pick that the choice cannot take is an error.
        if sym.choice.user_selection is not sym:
            return False
        return sym.choice.selection is not sym
    user = sym.user_value
    if sym.orig_type in (kconfiglib.BOOL, kconfiglib.TRISTATE):
        return sym.tri_value != user
    if sym.orig_type in (kconfiglib.INT, kconfiglib.HEX):
        try:
            return int(sym.str_value, 0) != int(user, 0)
        except ValueError:
            return True
    return sym.str_value != user


def explain(sym):
    user = sym.user_value
    if isinstance(user, int):
        user = kconfiglib.TRI_TO_STR[user]
    msg = (f"error: {sym.name_and_loc} was assigned the value '{user}' but got the value "
           f"'{sym.str_value}'.")
    if sym.direct_dep is not sym.kconfig.y and kconfiglib.expr_value(sym.direct_dep) == 0:
        msg += (f" Its dependencies are not met: {kconfiglib.expr_str(sym.direct_dep)} "
                f"(= n).")
    for node in sym.nodes:
        for low, high, cond in getattr(sym, "ranges", []):
            if kconfiglib.expr_value(cond):
                msg += f" Its range is [{low.str_value}, {high.str_value}]."
                break
        break
    return msg


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kconfig", required=True, help="root Kconfig file")
    ap.add_argument("--config", required=True, help=".config to write")
    ap.add_argument("--autoconf", required=True, help="autoconf.h to write")
    ap.add_argument("--sources", help="write the list of Kconfig files parsed here")
    ap.add_argument("fragments", nargs="*", help="Kconfig fragments, merged in order")
    args = ap.parse_args()

    try:
        kconf = kconfiglib.Kconfig(args.kconfig, warn_to_stderr=False)
    except kconfiglib.KconfigError as e:
        print(e, file=sys.stderr)
        return 1
    kconf.warn_assign_undef = True
    kconf.warn_assign_override = False
    kconf.warn_assign_redun = False

    digest_file = args.config + ".inputs"
    digest = fragments_digest(args.fragments)
    previous = None
    if os.path.exists(digest_file):
        with open(digest_file) as f:
            previous = f.read().strip()

    if previous == digest and os.path.exists(args.config):
        # Inputs unchanged: keep what menuconfig may have saved.
        kconf.load_config(args.config)
        checked = []
    else:
        replace = True
        board = set()
        for frag in args.fragments:
            kconf.load_config(frag, replace=replace)
            if replace:
                # The board's defconfig (first) may set options of subsystems an
                # application leaves out (CONFIG_CANOPEN_LOCK_CHECK without CANopen).
                board = set(user_assignments(kconf))
            replace = False
        checked = [s for s in user_assignments(kconf)
                   if s not in board or s.direct_dep.tri_value != 0]

    errors = [w for w in kconf.warnings]
    for sym in checked:
        if value_did_not_stick(sym):
            errors.append(explain(sym))

    if errors:
        for e in errors:
            print(e, file=sys.stderr)
        print("error: Aborting due to Kconfig warnings/errors above; nothing was written.",
              file=sys.stderr)
        return 1

    os.makedirs(os.path.dirname(args.config), exist_ok=True)
    os.makedirs(os.path.dirname(args.autoconf), exist_ok=True)
    kconf.write_config(args.config)
    kconf.write_autoconf(args.autoconf)
    with open(digest_file, "w") as f:
        f.write(digest + "\n")
    if args.sources:
        with open(args.sources, "w") as f:
            for name in sorted(set(kconf.kconfig_filenames)):
                f.write(os.path.join(kconf.srctree, name) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
