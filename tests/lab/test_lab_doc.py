"""docs/lab.md's slot tables are the slots' contracts, as the code derives them."""

from __future__ import annotations

from pathlib import Path

from ttt_sm.app.slots import SLOTS, contract

PAGE = Path(__file__).resolve().parents[2] / "docs" / "lab.md"


def _tables() -> str:
    out = []
    for s in SLOTS:
        out.append(f"### {s.name} (thesis section {s.section})\n")
        out.append("| name | kind | unit | why |\n|---|---|---|---|")
        out += [f"| `{e.name}` | {e.kind} | {e.unit or '-'} | {e.why} |" for e in contract(s.name)]
        out.append("")
    return "\n".join(out)


def test_the_page_lists_every_slot_contract_as_the_code_has_it():
    assert _tables() in PAGE.read_text(encoding="utf-8")
