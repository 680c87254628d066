#!/usr/bin/env python3
"""Checks libranger_can's layering: each layer includes only the layers below it.

    types.hpp, result.hpp, clock.hpp  <  wire/  <  transport/  <  control/  <  sim/

With --node, also checks that ranger_base/src and ranger_base/include hold no protocol knowledge:
no include of anything under ranger_can/wire/. Exit status 1 lists every offending include.
"""
import argparse
import pathlib
import re
import sys

ORDER = {"": 0, "wire": 1, "transport": 2, "control": 3, "sim": 4}
INCLUDE = re.compile(r'#include\s+[<"]ranger_can/(?:([a-z]+)/)?[a-z_]+\.hpp[>"]')


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", default=str(pathlib.Path(__file__).resolve().parents[1]))
    parser.add_argument("--node", action="store_true", help="also check ranger_base")
    args = parser.parse_args()
    root = pathlib.Path(args.root)
    bad = []
    lib = root / "libranger_can"
    for base in ("include/ranger_can", "src"):
        for path in sorted((lib / base).rglob("*.[ch]pp")):
            rel = path.relative_to(lib / base)
            layer = rel.parts[0] if len(rel.parts) > 1 else ""
            for m in INCLUDE.finditer(path.read_text(encoding="utf-8")):
                if ORDER.get(m.group(1) or "", 0) > ORDER.get(layer, 0):
                    bad.append(f"libranger_can/{base}/{rel}: {m.group(0)} (layer '{layer or 'types'}')")
    if args.node:
        for path in sorted((root / "ranger_base").rglob("*.[ch]pp")):
            if "test" in path.relative_to(root / "ranger_base").parts:
                continue
            for m in INCLUDE.finditer(path.read_text(encoding="utf-8")):
                if m.group(1) == "wire":
                    bad.append(f"{path.relative_to(root)}: {m.group(0)} (the node knows no frame)")
    for line in bad:
        print(line)
    print(f"check_layers: {len(bad)} offending include(s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
