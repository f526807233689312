"""The reports of ``ttt-sm lab grade``, built from ``results.jsonl``: grades.csv, report.json, report.html.

- ``grades.csv``: a row per student: status, score, passed, a column per
  check (``pass``, ``fail``, empty when the checks did not run), the error;
- ``report.json``: the same, with the class summary below;
- ``report.html``: one page for the teacher: the students x checks table, a
  heat map of the transitions each student's chart took (the coverage the
  checks measured, :class:`~ttt_sm.runtime.listeners.Coverage`), and the
  failures most of the class shares, each with a typical reason.

Everything here is read from the results file, so a report can be rebuilt
from what a grading left behind, interrupted or not (``--report-only``).
"""

from __future__ import annotations

import csv
import html
import io
import re
from collections import Counter
from pathlib import Path
from typing import Any

from ..files import write_atomic
from ..runtime.jsonable import dumps
from .grade import RESULTS, STATUSES, read_results

#: How many shared failures the reports list.
SHARED_FAILURES = 8


def check_names(results: list[dict[str, Any]]) -> list[str]:
    """The checks, in the order the exercise runs them (the first graded result's order, then any others)."""
    names: list[str] = []
    for r in results:
        for c in r.get("checks", []):
            if c["name"] not in names:
                names.append(c["name"])
    return names


def short_paths(reason: str) -> str:
    """A reason with the folders of its files left out (``.../checks/x.yaml:14`` -> ``x.yaml:14``)."""
    return re.sub(r"[^\s'\"]*/([^/\s'\"]+\.(yaml|py))", r"\1", reason)


def _pattern(reason: str) -> str:
    """A reason with its numbers and paths blurred, so two students failing the same way compare equal."""
    first = short_paths(reason.splitlines()[0] if reason else "")
    return re.sub(r"-?\d+(\.\d+)?", "#", first)


def shared_failures(results: list[dict[str, Any]], limit: int = SHARED_FAILURES) -> list[dict[str, Any]]:
    """The checks failed by the most students, each with how many, who, and its most common reason."""
    failed: dict[str, list[tuple[str, str]]] = {}
    for r in results:
        for c in r.get("checks", []):
            if not c["passed"]:
                failed.setdefault(c["name"], []).append((r["student"], c.get("reason", "")))
    out = []
    for name, who in sorted(failed.items(), key=lambda item: (-len(item[1]), item[0])):
        patterns = Counter(_pattern(reason) for _, reason in who)
        common, n = patterns.most_common(1)[0]
        typical = next(reason for _, reason in who if _pattern(reason) == common)
        out.append({"check": name, "failed_by": len(who), "students": [s for s, _ in who],
                    "typical_reason": typical, "students_with_that_reason": n})
    return out[:limit]


def transition_heat(results: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Every transition some student's chart has: which students' charts have it and which took it."""
    rows: dict[str, dict[str, Any]] = {}
    for r in results:
        taken = set(r.get("taken", []))
        for t in r.get("transitions", []):
            row = rows.setdefault(t, {"transition": t, "in_chart_of": [], "taken_by": []})
            row["in_chart_of"].append(r["student"])
            if t in taken:
                row["taken_by"].append(r["student"])
    return sorted(rows.values(), key=lambda row: (-len(row["in_chart_of"]), -len(row["taken_by"]), row["transition"]))


def summary(exercise: str, results: list[dict[str, Any]]) -> dict[str, Any]:
    """The class at a glance: how many students, graded, passed, and each status."""
    statuses = Counter(r["status"] for r in results)
    return {"exercise": exercise, "students": len(results), "passed": sum(bool(r["passed"]) for r in results),
            "statuses": {s: statuses[s] for s in STATUSES if statuses[s]}}


def write_csv(path: Path, results: list[dict[str, Any]], names: list[str]) -> None:
    f = io.StringIO(newline="")  # the whole table, then written whole (write_atomic)
    out = csv.writer(f)
    out.writerow(["student", "status", "score", "total", "passed", *names, "error"])
    for r in results:
        by_name = {c["name"]: c["passed"] for c in r.get("checks", [])}
        cells = ["" if n not in by_name else "pass" if by_name[n] else "fail" for n in names]
        out.writerow([r["student"], r["status"], r["score"], r["total"], "yes" if r["passed"] else "no",
                      *cells, r.get("error", "")])
    write_atomic(path, f.getvalue())


_STYLE = """
body { font: 14px/1.4 system-ui, sans-serif; margin: 24px; color: #222; }
h1 { font-size: 20px; } h2 { font-size: 16px; margin-top: 28px; }
table { border-collapse: collapse; margin: 8px 0; }
th, td { border: 1px solid #ccc; padding: 3px 7px; vertical-align: top; }
th { background: #f3f3f3; text-align: left; font-weight: 600; }
td.pass { background: #c8ebc8; text-align: center; } td.fail { background: #f6c4c4; text-align: center; }
td.none { background: #eee; } td.num { text-align: right; }
td.taken { background: #2e8b57; } td.untaken { background: #f0d7d7; } td.absent { background: #fff; }
.status-graded { color: #222; } .status-other { color: #a00; font-weight: 600; }
.err { font-family: monospace; font-size: 12px; max-width: 520px; }
.reason { font-family: monospace; font-size: 12px; white-space: pre-wrap; max-width: 760px; }
th.rot { writing-mode: vertical-rl; transform: rotate(180deg); font-weight: 400; white-space: nowrap; }
.key span { display: inline-block; width: 14px; height: 14px; vertical-align: middle; margin: 0 4px 0 12px;
            border: 1px solid #ccc; }
"""


def _e(text: Any) -> str:
    return html.escape(str(text), quote=True)


def _short(name: str, width: int = 42) -> str:
    return name if len(name) <= width else name[: width - 1] + "\u2026"


def render_html(exercise: str, results: list[dict[str, Any]], names: list[str]) -> str:
    """The teacher's page: the class summary, students x checks, the transition heat map, shared failures."""
    s = summary(exercise, results)
    statuses = ", ".join(f"{n} {status}" for status, n in s["statuses"].items())
    out = [f"<!doctype html><html><head><meta charset='utf-8'><title>{_e(exercise)}: grades</title>",
           f"<style>{_STYLE}</style></head><body>",
           f"<h1>{_e(exercise)}: {s['students']} students, {s['passed']} passed every check</h1>",
           f"<p>{_e(statuses)}</p>", "<h2>Students and checks</h2><table><tr><th>student</th><th>status</th>",
           "<th>score</th>"]
    out += [f"<th class='rot' title='{_e(n)}'>{_e(_short(n))}</th>" for n in names]
    out.append("<th>error</th></tr>")
    for r in results:
        by_name = {c["name"]: c for c in r.get("checks", [])}
        kind = "graded" if r["status"] == "graded" else "other"
        score = f"{r['score']}/{r['total']}" if r["total"] else "-"
        out.append(f"<tr><td>{_e(r['student'])}</td><td class='status-{kind}'>{_e(r['status'])}</td>"
                   f"<td class='num'>{score}</td>")
        for n in names:
            c = by_name.get(n)
            if c is None:
                out.append("<td class='none'></td>")
            elif c["passed"]:
                out.append(f"<td class='pass' title='{_e(n)}'>\u2713</td>")
            else:
                out.append(f"<td class='fail' title='{_e(short_paths(c.get('reason', '')))}'>\u2717</td>")
        out.append(f"<td class='err'>{_e(r.get('error', ''))}</td></tr>")
    out.append("</table>")

    heat = transition_heat(results)
    checked = [r for r in results if r.get("checks")]  # the checks ran (a memory limit may strike in one)
    charted = [r for r in results if r.get("transitions")]  # a chart cut short by a limit has its coverage too
    out.append("<h2>Transitions each chart took</h2>")
    out.append("<p class='key'>Each student's own transitions, as the checks' coverage counted them:"
               "<span style='background:#2e8b57'></span>taken<span style='background:#f0d7d7'></span>in the chart,"
               " never taken<span></span>not in that chart</p>")
    if heat:
        out.append("<table><tr><th>transition</th><th>taken by</th>")
        out += [f"<th class='rot'>{_e(r['student'])}</th>" for r in charted]
        out.append("</tr>")
        for row in heat:
            out.append(f"<tr><td class='err'>{_e(row['transition'])}</td>"
                       f"<td class='num'>{len(row['taken_by'])}/{len(row['in_chart_of'])}</td>")
            for r in charted:
                cls = ("taken" if r["student"] in row["taken_by"] else
                       "untaken" if r["student"] in row["in_chart_of"] else "absent")
                out.append(f"<td class='{cls}' title='{_e(r['student'])}: {_e(row['transition'])}'></td>")
            out.append("</tr>")
        out.append("</table>")
    else:
        out.append("<p>No chart was graded.</p>")

    out.append("<h2>The failures most of the class shares</h2>")
    shared = shared_failures(results)
    if shared:
        out.append("<table><tr><th>check</th><th>failed by (of those checked)</th><th>a typical reason</th></tr>")
        for f in shared:
            out.append(f"<tr><td>{_e(f['check'])}</td><td class='num'>{f['failed_by']}/{len(checked)}</td>"
                       f"<td class='reason'>{_e(short_paths(f['typical_reason']))}"
                       f"<br>({f['students_with_that_reason']} of them this way)</td></tr>")
        out.append("</table>")
    else:
        out.append("<p>No check failed.</p>")
    others = [r for r in results if r["status"] != "graded"]
    if others:
        out.append(f"<p>{len(others)} did not finish their checks: "
                   + "; ".join(f"{_e(r['student'])} ({_e(r['status'])})" for r in others) + ".</p>")
    out.append("</body></html>\n")
    return "".join(out)


def build_reports(folder: Path) -> dict[str, Any]:
    """Write grades.csv, report.json and report.html in `folder` from its results.jsonl; the report as a dict."""
    header, by_student = read_results(folder / RESULTS)
    exercise = str(header.get("exercise", "?"))
    results = [by_student[s] for s in sorted(by_student)]
    names = check_names(results)
    write_csv(folder / "grades.csv", results, names)
    report = {**summary(exercise, results), "checks": names, "shared_failures": shared_failures(results),
              "transitions": transition_heat(results), "results": results}
    write_atomic(folder / "report.json", dumps(report, indent=2) + "\n")
    write_atomic(folder / "report.html", render_html(exercise, results, names))
    return report
