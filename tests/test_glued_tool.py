"""tools/glued.py: the comparison that shows a change of layout left the book's numbers as they were."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))

import glued  # noqa: E402


def test_two_dumps_differ_exactly_where_a_value_changed_or_is_missing():
    before = {"chapters/05_stability": {"p_sim_gap": "'3e-09'", "p_stable": "1.1315"}, "intro": {"a": "1"}}
    assert glued.differences(before, before) == []
    after = {"chapters/05_stability": {"p_sim_gap": "'3e-09'", "p_stable": "1.1316"}, "intro": {}}
    assert glued.differences(before, after) == [
        "chapters/05_stability: p_stable: 1.1315 -> 1.1316", "intro: a: 1 -> (absent)"]


def test_compare_exits_1_on_a_difference(tmp_path, capsys):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    a.write_text('{"p": {"x": "1"}}')
    b.write_text('{"p": {"x": "2"}}')
    assert glued.main(["compare", str(a), str(a)]) == 0
    assert glued.main(["compare", str(a), str(b)]) == 1 and "p: x: 1 -> 2" in capsys.readouterr().out
