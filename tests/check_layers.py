#!/usr/bin/env python3
"""Checks libranger_can's layering: each layer includes only the layers below it.

    types.hpp, result.hpp, clock.hpp  <  wire/  <  transport/  <  control/  <  sim/  <  frontend/

Also checks that the ROS node (ranger_base/src and ranger_base/include) holds no protocol
knowledge: no include of anything under ranger_can/wire/, and no name from the protocol namespace
(`protocol::`, `ranger::protocol`): it speaks the control layer's vocabulary
(control/vocabulary.hpp). Exit status 1 lists every offence.
"""
import argparse
import pathlib
import re
import sys

ORDER = {"": 0, "wire": 1, "transport": 2, "control": 3, "sim": 4, "frontend": 5}
INCLUDE = re.compile(r'#include\s+[<"]ranger_can/(?:([a-z]+)/)?[a-z_]+\.hpp[>"]')
PROTOCOL_NAME = re.compile(r"\bprotocol::|\branger::protocol\b")


def library_offences(root):
    bad = []
    lib = root / "libranger_can"
    for base in ("include/ranger_can", "src"):
        for path in sorted((lib / base).rglob("*.[ch]pp")):
            rel = path.relative_to(lib / base)
            layer = rel.parts[0] if len(rel.parts) > 1 else ""
            for m in INCLUDE.finditer(path.read_text(encoding="utf-8")):
                if ORDER.get(m.group(1) or "", 0) > ORDER.get(layer, 0):
                    bad.append(f"libranger_can/{base}/{rel}: {m.group(0)} (layer '{layer or 'types'}')")
    return bad


def node_offences(root):
    bad = []
    for sub in ("src", "include"):
        for path in sorted((root / "ranger_base" / sub).rglob("*.[ch]pp")):
            rel = path.relative_to(root)
            for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
                for m in INCLUDE.finditer(line):
                    if m.group(1) == "wire":
                        bad.append(f"{rel}:{number}: {m.group(0)} (the node knows no frame)")
                m = PROTOCOL_NAME.search(line)
                if m:
                    bad.append(f"{rel}:{number}: {m.group(0)} (the node speaks the control "
                               "layer's vocabulary: ranger_can/control/vocabulary.hpp)")
    return bad


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", default=str(pathlib.Path(__file__).resolve().parents[1]))
    parser.add_argument("--node", action="store_true",
                        help="(kept for old callers: ranger_base is always checked)")
    args = parser.parse_args()
    root = pathlib.Path(args.root)
    bad = library_offences(root)
    if (root / "ranger_base").is_dir():
        bad += node_offences(root)
    for line in bad:
        print(line)
    print(f"check_layers: {len(bad)} offence(s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
