"""A number carries its kind, and its kind decides how it is written (lib.machinery.kinds).

The fast tests check the rounding itself against exact decimal arithmetic; the book tests read
every page as it was executed for the build (the execution cache) and check, for each glued
number the prose writes, that a bound is rounded toward safety and that the words before a number
("at least", "at most", ...) are true of the printed value."""

from __future__ import annotations

import math
import re
import sys
from ast import literal_eval
from decimal import Decimal
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lib.machinery import kinds
from lib.machinery.kinds import Kind, Number, round_directed

ROOT = Path(__file__).resolve().parents[1]
FMTS = [".1f", ".2f", ".3f", ".4f", ".1e", ".2e", ".2g", ".3g", ".4g"]


@settings(max_examples=400, deadline=None)
@given(st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_subnormal=False), st.sampled_from(FMTS))
def test_a_value_rounded_down_is_never_above_it_and_up_never_below(x, fmt):
    down, up, near = (round_directed(x, fmt, r) for r in ("down", "up", "nearest"))
    exact = Decimal(repr(x))          # the value as Python writes it, within half an ulp of the double
    assert Decimal(down) <= exact <= Decimal(up)
    # the two directed roundings are the neighbours of the exact value on the format's grid:
    # the nearest is one of them (ties aside, where both are equally near)
    assert near in (down, up) or abs(Decimal(near) - exact) <= abs(Decimal(down) - exact)


def test_the_certified_bound_of_the_issue_is_written_below_itself():
    # Chapter 8's bound was 0.10769 m and printed 0.108 (to nearest, above the bound, and above
    # a motion that reaches 0.10776 m)
    assert kinds.lower_bound(0.10769, ".3f").text() == "0.107"
    assert kinds.lower_bound(0.10769, ".4f").text() == "0.1076"
    assert kinds.best_found(0.10776, ".4f").text() == "0.1078"
    # where rounding up and to nearest differ (issue 59's surviving mutant): a motion found is written up
    assert kinds.best_found(0.10771, ".4f").text() == "0.1078" and kinds.exact(0.10771, ".4f").text() == "0.1077"
    assert kinds.upper_bound(0.10770, ".3g").text() == "0.108"
    assert kinds.at_most(0.10761, ".3f").text() == "0.108" and kinds.at_least(0.10769, ".3f").text() == "0.107"
    assert kinds.exact(0.10769, ".3f").text() == "0.108"


def test_a_value_with_a_short_decimal_is_not_pushed_past_it_by_its_binary_tail():
    # 0.19 is stored as 0.19000000000000000222...: rounded up to 3 decimals it stays 0.190
    assert round_directed(0.19, ".3f", "up") == "0.190" and round_directed(0.29, ".2f", "down") == "0.29"


def test_an_estimate_is_written_with_its_error_rounded_up():
    assert kinds.estimate(0.3012, 0.0212, ".2f").text() == "0.30 ± 0.03"
    assert kinds.count(364, 10000).text() == "364"


def test_a_glued_number_carries_its_value_and_kind_beside_its_text():
    from IPython.core.formatters import format_display_data
    bundle, _ = format_display_data(kinds.lower_bound(0.10769, ".4f"))
    assert literal_eval(bundle["text/plain"]) == "0.1076"
    assert bundle[kinds.MIME]["value"] == 0.10769 and bundle[kinds.MIME]["kind"] == Kind.LOWER.value


@pytest.mark.parametrize("bad, match", [
    (lambda: kinds.lower_bound(float("nan")), "value"),
    (lambda: kinds.lower_bound(1.0, "4f"), "fmt"),
    (lambda: kinds.lower_bound(1.0, ".4d"), "fmt"),
    (lambda: Number(1.0, Kind.EXACT, stderr=0.1), "stderr"),
    (lambda: Number(1.0, Kind.ESTIMATE), "stderr"),
    (lambda: kinds.estimate(1.0, -0.1), "stderr"),
    (lambda: kinds.count(3.5), "count"),
    (lambda: kinds.count(5, total=4), "total"),
    (lambda: Number(1.0, "no such kind"), "no such kind"),
    (lambda: round_directed(1.0, ".2f", "sideways"), "rounding"),
])
def test_a_malformed_number_is_refused_naming_what_is_wrong(bad, match):
    with pytest.raises(ValueError, match=match):
        bad()


# ----------------------------------------------------------------- the words before a number

#: words that make the number after them a floor ("at least x": x must not exceed the value)
FLOOR_WORDS = ("at least", "no less than", "no closer than", "closer to the eight than")
#: words that make it a ceiling ("at most x": x must not fall below the value). "up to", "below" and
#: "under" are not read: they also state a range ("held up to w = x", "below x it holds"), where
#: the safe side is the other one; such a number is glued with its kind (lower_bound, upper_bound)
CEILING_WORDS = ("at most", "no more than", "within")
#: every word that bounds the number after it (issue 57): the number must carry a kind whose rounding
#: says which side is safe (a bound, a motion found), or be a count or a whole number (an input such as
#: "up to 8 periods"), so that the sentence is true on any CPU by construction, not by how one
#: machine's last digit rounded. A plain float here is refused, whatever it rounds to on this machine.
BOUND_WORDS = FLOOR_WORDS + CEILING_WORDS + ("below", "above", "up to", "under")
#: the kinds that may follow a bounding word
BOUND_KINDS = tuple(k.value for k in kinds.BOUNDS) + (Kind.COUNT.value, Kind.SETTING.value)
#: a computed number below this in magnitude is at round-off scale (kinds.ROUNDOFF): printed as
#: measured, it is the last bits of one machine. It is printed instead as the bound its method
#: guarantees (kinds.within_accuracy), with the method named beside it; a setting is exact.
ROUNDOFF = kinds.ROUNDOFF
GLUE_TEXT = re.compile(r"\{glue:text\}`(?:[^`:]+::)?([A-Za-z0-9_]+)(?::([^`]*))?`")


def words_before(source: str, start: int) -> str:
    """The few words before a glue role, on its line or the one before, lower case."""
    head = re.sub(r"\s+", " ", source[max(0, start - 40):start]).lower()
    return head


def bounding_word(head: str) -> str | None:
    """The bounding word (``BOUND_WORDS``) that the words before a number end with, if any."""
    tail = head.rstrip()
    return next((w for w in BOUND_WORDS if re.search(rf"\b{w}$", tail)), None)


def reading(head: str) -> str | None:
    """'floor', 'ceiling' or None: what the words just before a number claim of it."""
    tail = head.rstrip()
    for words, kind in ((FLOOR_WORDS, "floor"), (CEILING_WORDS, "ceiling")):
        if any(tail.endswith(w) for w in words):
            return kind
    return None


def test_the_words_before_a_number_are_read_as_a_floor_or_a_ceiling():
    assert reading("no controller can keep c closer to the eight than ") == "floor"
    assert reading("and c ends at least ") == "floor"
    assert reading("multipliers of modulus at most ") == "ceiling"
    assert reading("the ratio reaches ") is None
    assert reading("the circle is held up to ") is None          # a range: its safe side is below


def rendered(text_plain: str, fmt: str | None) -> str:
    """What myst-nb writes for a glued value with a format spec (its own function)."""
    from myst_nb.core.variables import format_plain_text
    return format_plain_text(text_plain, fmt or "")


def check_page(source: str, glued: dict) -> list[str]:
    """Every violation of the kinds' rule on one page: a bound or a motion found written with a
    format spec, or rounded the wrong way; a number after floor or ceiling words written on the
    wrong side of its value."""
    bad = []
    for m in GLUE_TEXT.finditer(source):
        key, fmt = m.group(1), m.group(2)
        if key not in glued:
            continue
        text_plain, record = glued[key]
        try:
            shown = float(rendered(text_plain, fmt).split(" ± ")[0])
            value = record["value"] if record else float(literal_eval(text_plain))
        except (ValueError, TypeError, SyntaxError):
            continue                                       # a word, not a number
        if record and record["kind"] != Kind.COUNT.value and fmt:
            bad.append(f"{key}: a {record['kind']} written with the spec {fmt!r} (rounds it again)")
        if record and Kind(record["kind"]).rounding == "down" and shown > value:
            bad.append(f"{key}: a lower bound {value!r} printed above itself as {shown}")
        if record and Kind(record["kind"]).rounding == "up" and shown < value:
            bad.append(f"{key}: an upper bound {value!r} printed below itself as {shown}")
        head = words_before(source, m.start())
        word = bounding_word(head)
        kind = record["kind"] if record else None
        if word and kind not in BOUND_KINDS and not (kind is None and float(value).is_integer()):
            bad.append(f"{key}: '{word} {shown}' is a {kind or 'plain number'}, not a bound: glue it with "
                       "its kind (lower_bound, upper_bound, best_found) so its rounding is on the safe side")
        if 0 < abs(value) < ROUNDOFF and kind not in BOUND_KINDS:
            bad.append(f"{key}: {value!r} is at round-off scale, printed as a {kind or 'plain number'}: "
                       "print the bound its method guarantees, and name the method")
        claim = reading(head)
        if claim == "floor" and shown > value:
            bad.append(f"{key}: 'at least {shown}' but the value is {value!r}")
        if claim == "ceiling" and shown < value:
            bad.append(f"{key}: 'at most {shown}' but the value is {value!r}")
    return bad


def test_the_page_check_catches_a_bound_rounded_up_and_a_floor_above_its_value():
    src = "no controller keeps C closer to the eight than {glue:text}`b:.3f` m"
    assert check_page(src, {"b": (repr(0.10769), None)})          # 0.108 > 0.10769
    bound = kinds.lower_bound(0.10769, ".4f")
    assert not check_page("closer to the eight than {glue:text}`b` m", {"b": (repr(bound.text()), bound.record())})
    assert check_page("than {glue:text}`b:.3f` m", {"b": (repr(bound.text()), bound.record())})
    ceiling = kinds.upper_bound(0.0281, ".2f")                                           # 0.03 >= 0.0281
    assert not check_page("at most {glue:text}`r`", {"r": (repr(ceiling.text()), ceiling.record())})
    assert any("'at most 0.02' but" in b for b in check_page("at most {glue:text}`r:.2f`", {"r": (repr(0.0241), None)}))


def test_a_plain_float_after_a_bounding_word_is_refused_whatever_it_rounds_to():
    # Chapter 5's p_sim_gap: 'within 5e-14' read true on one CPU (5.4e-14 rounded up) and false on
    # another (5.1e-14 rounded down). A plain float after a bounding word fails on both.
    for value in (5.4e-14 * 1e10, 5.1e-14 * 1e10):          # the same check away from round-off
        bad = check_page("ends within {glue:text}`g:.0e` rad of it", {"g": (repr(value), None)})
        assert any("not a bound" in b for b in bad), bad
    for word in ("below", "above", "up to", "under", "at least", "at most", "within"):
        assert check_page(f"it is {word} {{glue:text}}`g:.2f` m", {"g": (repr(0.123), None)}), word
    bound = kinds.upper_bound(0.123, ".2f")
    assert not check_page("within {glue:text}`g` m", {"g": (repr(bound.text()), bound.record())})
    # a whole number (an input: "up to 8 periods") and a count need no kind; "below" inside a word does not bound
    assert not check_page("up to {glue:text}`n` periods", {"n": ("8", None)})
    assert not check_page("the belowground {glue:text}`g:.2f` m", {"g": (repr(0.123), None)})


def test_a_value_at_round_off_scale_is_refused_unless_printed_as_a_bound():
    assert any("round-off" in b for b in check_page("differs by {glue:text}`d:.0e` rad", {"d": (repr(5.1e-14), None)}))
    est = kinds.exact(5.1e-14, ".1e")
    assert any("round-off" in b for b in check_page("is {glue:text}`d` rad", {"d": (repr(est.text()), est.record())}))
    tol = kinds.upper_bound(2.1e-10, ".0e")
    assert not check_page("within {glue:text}`d` rad", {"d": (repr(tol.text()), tol.record())})
    assert not check_page("is {glue:text}`d` rad", {"d": ("0.0", None)})       # an exact zero is not round-off


def test_a_round_off_value_is_printed_as_its_methods_bound_ten_times_above_it():
    assert kinds.within_accuracy(5.1e-14, 2.1e-9).text() == "3e-09"         # rounded up, as a bound
    assert kinds.within_accuracy(-5.4e-14, 2.1e-9).kind is Kind.CEILING
    with pytest.raises(ValueError, match="ten times"):
        kinds.within_accuracy(3e-10, 2.1e-9)                                 # not round-off: a margin of 7
    with pytest.raises(ValueError, match="measured"):
        kinds.within_accuracy(float("nan"), 1e-9)


def test_a_setting_is_written_exactly_or_refused():
    assert kinds.setting(1e-10, ".0e").text() == "1e-10" and kinds.setting(0.05, ".2f").text() == "0.05"
    assert kinds.setting(0.1 * 1e-3, ".1g").text() == "0.0001"          # a product's last bit aside
    with pytest.raises(ValueError, match="exactly"):
        kinds.setting(0.05, ".1f")


def executed_pages() -> dict[str, dict]:
    """Each page's glued values as the build executed it: page -> {key: (text/plain, record)}
    (``tools/glued.py``, which also compares two builds' values)."""
    sys.path.insert(0, str(ROOT / "tools"))
    import glued
    return glued.executed_glue(ROOT)


@pytest.mark.book
def test_every_glued_bound_in_the_built_book_reads_on_its_safe_side(built_book):
    pages = executed_pages()
    assert len(pages) >= 10, sorted(pages)
    bad, bounds = [], 0
    for page, glued in pages.items():
        bad += [f"{page}: {b}" for b in check_page((ROOT / f"{page}.md").read_text(), glued)]
        bounds += sum(1 for _, rec in glued.values() if rec and rec["kind"] != Kind.COUNT.value)
    assert bounds >= 5, "the book glues its bounds and motions found as numbers with their kinds"
    assert not bad, "\n".join(bad)
