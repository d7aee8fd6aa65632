"""The failing cases of a DDG_FUZZ_RECORD file, grouped by cause:
`python tests/fuzz_cases/report.py RECORD.jsonl`."""
from __future__ import annotations


def report(record_path: str) -> str:
    """The failing cases of a DDG_FUZZ_RECORD file grouped by cause (case id, exit code, first
    line of stderr or the exception), then the counts and the slowest cases."""
    import json
    from collections import defaultdict

    entries = {}
    for line in open(record_path):
        if line.strip():
            entry = json.loads(line)
            entries[entry["id"]] = entry  # the last run of a case wins
    rows = list(entries.values())
    failing = [e for e in rows if not e["ok"]]
    groups = defaultdict(list)
    for e in failing:
        groups[e["cause"]].append(e)
    kinds = defaultdict(int)
    for e in rows:
        kinds[("subprocess" if e["id"].startswith("subprocess-") else e["expect"])] += 1
    lines = [f"fuzz cases recorded: {len(rows)} ({', '.join(f'{k} {v}' for k, v in sorted(kinds.items()))}); "
             f"failing: {len(failing)} in {len(groups)} causes", ""]
    for cause, members in sorted(groups.items(), key=lambda kv: (-len(kv[1]), kv[0])):
        lines.append(f"== {cause} ({len(members)})")
        for e in sorted(members, key=lambda e: e["id"]):
            text = e["detail"] if e["detail"] and e["detail"] != e["stderr"] else e["stderr"]
            if e["stderr"] and e["detail"] and e["detail"] != e["stderr"]:
                text = f"{e['detail']} || stderr: {e['stderr']}"
            lines.append(f"  {e['id']}  exit={e['code']}  {text[:220]}")
        lines.append("")
    slow = sorted((e for e in rows if e["seconds"] > 1.0 and not e["id"].startswith(("run-", "subprocess-"))),
                  key=lambda e: -e["seconds"])
    lines.append(f"in-process cases slower than 1 s: {len(slow)}")
    lines += [f"  {e['id']}  {e['seconds']:.2f} s" for e in slow[:20]]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    import sys

    if len(sys.argv) != 2:
        sys.exit("usage: python tests/fuzz_cases/report.py RECORD.jsonl")
    sys.stdout.write(report(sys.argv[1]))
