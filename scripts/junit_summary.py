"""Reads every JUnit XML report under a directory (stdlib only).

  junit_summary.py DIR [--files|--measured|--total]
    --files     one line per report: 'PATH: N passed, N failed, N skipped'
    --measured  the margins the tests measured under the run's load: each '[measured] ...' line
                of a report's output (rostest, rosunit) and each testsuite property 'measured'
                (the pytest suites' conftest.py), prefixed with the report's path
    --total     the closing line 'tests: N passed, N failed, N skipped' (the default; with no
                option, the files and then the total, as before)
"""
import pathlib
import sys
import xml.etree.ElementTree as ET


def read(path):
    """(passed, failed, skipped, measured lines) of one report."""
    passed = failed = skipped = 0
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as e:
        return 0, 1, 0, [f"unreadable report ({e})"]
    for case in root.iter("testcase"):
        if case.find("failure") is not None or case.find("error") is not None:
            failed += 1
        elif case.find("skipped") is not None or case.get("status") in ("notrun", "disabled"):
            skipped += 1
        else:
            passed += 1
    measured = []
    for out in root.iter("system-out"):
        measured += [line.strip() for line in (out.text or "").splitlines()
                     if line.strip().startswith("[measured]")]
    for prop in root.iter("property"):
        if prop.get("name") == "measured":
            measured.append("[measured] " + prop.get("value", ""))
    return passed, failed, skipped, measured


def main():
    args = sys.argv[1:]
    modes = {a for a in args if a.startswith("--")}
    unknown = modes - {"--files", "--measured", "--total"}
    if unknown:
        sys.exit(f"junit_summary.py: unknown option {' '.join(sorted(unknown))} "
                 "(--files, --measured, --total)")
    dirs = [a for a in args if not a.startswith("--")]
    base = pathlib.Path(dirs[0] if dirs else "build/test-results")
    modes = modes or {"--files", "--total"}
    total = [0, 0, 0]
    for path in sorted(base.rglob("*.xml")):
        p, f, s, measured = read(path)
        total = [total[0] + p, total[1] + f, total[2] + s]
        name = path.relative_to(base)
        if "--files" in modes:
            print(f"  {name}: {p} passed, {f} failed, {s} skipped")
        if "--measured" in modes:
            for line in measured:
                print(f"  {name}: {line}")
    if "--total" in modes:
        print(f"tests: {total[0]} passed, {total[1]} failed, {total[2]} skipped")


if __name__ == "__main__":
    main()
