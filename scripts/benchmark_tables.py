"""Rewrites the generated regions of a document (docs/benchmarks.md, docs/reliability.md) from
one scripts/benchmarks.sh run.

A region is the text between `<!-- bench:NAME -->` and `<!-- /bench:NAME -->`; NAME is a result
in the results folder: NAME.json (Google Benchmark, medians shown) or NAME.txt (an accuracy
binary's output, whose Markdown table lines are kept). Each region gets a stamp line with the
date the result was written, the core count and the command. Regions without a result are left
as they are.
"""
import datetime
import json
import pathlib
import re
import sys


def gbench_table(path):
    data = json.loads(path.read_text())
    rows = ["| benchmark | median | unit | counters |", "| --- | --- | --- | --- |"]
    for b in data["benchmarks"]:
        if b.get("aggregate_name") != "median":
            continue
        name = b["run_name"]
        counters = ", ".join(
            f"{k} {v:.4g}" for k, v in b.items()
            if k not in ("name", "run_name", "run_type", "repetitions", "threads", "aggregate_name",
                         "aggregate_unit", "iterations", "real_time", "cpu_time", "time_unit",
                         "family_index", "per_family_instance_index", "repetition_index", "label")
            and isinstance(v, (int, float)))
        rows.append(f"| `{name}` | {b['real_time']:.4g} | {b['time_unit']} | {counters} |")
    return "\n".join(rows)


def text_table(path):
    """The table lines of an output; separate tables stay separated by a blank line."""
    out = []
    for line in path.read_text().splitlines():
        if line.startswith("|"):
            out.append(line)
        elif out and out[-1] != "":
            out.append("")
    return "\n".join(out).strip("\n")


def main(results, doc, cores):
    results = pathlib.Path(results)
    doc = pathlib.Path(doc)
    text = doc.read_text()

    def replace(m):
        name = m.group(1)
        for suffix, make in ((".json", gbench_table), (".txt", text_table)):
            result = results / (name + suffix)
            if result.exists():
                command = (results / (name + ".command")).read_text().strip()
                body = make(result)
                measured = datetime.date.fromtimestamp(result.stat().st_mtime).isoformat()
                stamp = f"Measured {measured} on {cores} cores: `{command}`"
                return f"<!-- bench:{name} -->\n{stamp}\n\n{body}\n<!-- /bench:{name} -->"
        return m.group(0)

    text = re.sub(r"<!-- bench:(\w+) -->.*?<!-- /bench:\1 -->", replace, text, flags=re.S)
    doc.write_text(text)


if __name__ == "__main__":
    main(*sys.argv[1:4])
