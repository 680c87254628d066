"""Counts test cases across every JUnit XML report under a directory (stdlib only).

Prints one line per report file and a final 'tests: N passed, N failed, N skipped' line.
"""
import pathlib
import sys
import xml.etree.ElementTree as ET


def count(path):
    passed = failed = skipped = 0
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as e:
        print(f"  {path}: unreadable report ({e})")
        return 0, 1, 0
    for case in root.iter("testcase"):
        if case.find("failure") is not None or case.find("error") is not None:
            failed += 1
        elif case.find("skipped") is not None or case.get("status") in ("notrun", "disabled"):
            skipped += 1
        else:
            passed += 1
    return passed, failed, skipped


def main():
    base = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "build/test-results")
    total = [0, 0, 0]
    for path in sorted(base.rglob("*.xml")):
        p, f, s = count(path)
        total = [total[0] + p, total[1] + f, total[2] + s]
        print(f"  {path.relative_to(base)}: {p} passed, {f} failed, {s} skipped")
    print(f"tests: {total[0]} passed, {total[1]} failed, {total[2]} skipped")


if __name__ == "__main__":
    main()
