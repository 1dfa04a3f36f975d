"""What the book found, for its front page (``intro.md``): each finding a report row
(:mod:`lib.paper.report`), its status and its figure of merit, read through
:func:`lib.paper.report.outcome`, so the front page quotes the computation the report and the
chapters show, computed once per book build.

Every number the front page states is one of :func:`front_page`'s, and each carries a unit
and a reading in :data:`LABELS`: what it counts or measures, and in what (a count is of
points, angle limits or runs; a distance in m, an angle in rad). The same holds for the
numbers of each chapter's findings box. ``tests/test_findings_labels.py`` checks that the page
writes each number beside its unit and its reading.
"""

from __future__ import annotations

import math

import numpy as np

from ..machinery.cache import cached
from ..optimal.entry import ENTRY_PERIODS
from ..optimal.studies.study import PAPER_CAP
from ..params import Body, Gains
from ..percussion import percussion_fig5_map
from ..rotation.circle_global import bistable_window
from ..rotation.fig5 import fig5_map
from ..machinery.kinds import Number, best_found, upper_bound, within_accuracy
from ..integrators.smooth import Integration
from ..optimal.studies.margins import SECOND_EIGHT
from ..simulate import OPEN_LOOP_HORIZON
from ..trajectories import eight
from . import studies
from .extensions import R0, THETA0, fig5_readings, mirror_gap
from .outcomes import Outcome
from .report import SWEEP_DEG, _angle_sweep, outcome, status
from .studies import open_loop_gap

__all__ = ["FINDINGS", "LABELS", "WHAT_WE_FOUND", "findings", "front_page", "what_we_found"]

#: the report rows the front page states, each with the status it states
FINDINGS = {
    "eq6": "corrected", "thm6": "refuted", "thm7": "misapplied", "stlc": "refuted", "gas": "refuted",
    "window": "extended", "fig3": "reproduced", "limit-mirror": "extended", "chaos": "reproduced",
    "quasi": "reproduced under an added condition", "fig5": "not reproducible as stated", "fig5-map": "extended",
    "weight-limit": "extended", "percussion-map": "extended", "cap-bound": "extended", "second-eight": "extended",
}

#: for each page, the numbers its findings box glues: name -> (unit, reading). The unit is written
#: within a few words of the number (before it for "row 2"), the reading in the same bullet; a
#: unit "" marks a pure number (a weight, a multiplier), whose reading says what it is
LABELS = {
    "intro": {
        "fd_eq6_t": ("s", "inputs"), "fd_eq6_pos": ("m", "centre of mass"), "fd_eq6_heading": ("rad", "heading"),
        "fd_fig3": ("rad", "ranging"), "fd_mirror_heading": ("rad", "heading"),
        "fd_mirror_rate": ("rad/s", "turning rate"), "fd_mirror_pos": ("m", "centres of mass"),
        "fd_chaos": ("1/s", "Lyapunov exponent"),
        "fd_chaos_deg": ("degree", "angle limit"),
        "fd_chaos_n": ("angle limits", "chaotic"),
        "fd_chaos_cap_n": ("angle limits", "cap"), "fd_angles": ("angle limits", "chaotic"),
        "fd_window_lo": ("m", "window"), "fd_window_hi": ("m", "window"),
        "fd_grid": ("points", "grid"), "fd_not_held": ("points", "not held"), "fd_lost": ("points", "lost"),
        "fd_turns": ("points", "turns round"), "fd_weight": ("", "weight"),
        "fd_p_held": ("points", "law for P"), "fd_p_grid": ("points", "held"),
        "fd_paper_held": ("points", "paper's law"), "fd_bound": ("m", "lower bound"),
        "fd_paper_cap": ("m", "paper's law"), "fd_opt_cap": ("m", "controller tracking the motion found best"),
        "fd_e2_R": ("m", "second eight"), "fd_e2_Theta": ("rad/s", "second eight"),
        "fd_e2_ratio": ("times", "second eight"), "fd_e1_ratio": ("times", "paper's law"),
        "fd_entry_reached": ("settings", "paper's start"), "fd_entry_n": ("limit settings", "entry"),
        "fd_entry_periods": ("periods", "entry"),
    },
    "chapters/01_model": {
        "n_wrong_rows": ("row", "drift"), "wrong_row": ("row", "wrong sign"),
        "ol_gap_end": ("m", "centre of mass"), "ol_t_end": ("s", "after"),
    },
    "chapters/02_controllability": {"n_wrong": ("entries", "wrong"), "n_entries": ("entries", "printed")},
    "chapters/03_tracking": {
        "orb_range_deg": ("degrees", "range"), "orb_mu1": ("", "Floquet multiplier"),
        "mm_circle_m20": ("m", "position error"), "mm_eight_m20": ("m", "position error"),
    },
    "chapters/04_limits": {
        "free_n_chaotic": ("angle limits", "chaotic"), "bif_n": ("angle limits", "chaotic"),
        "free_min_z": ("standard errors", "chaotic"), "capsw_n_chaotic": ("angle limits", "cap"),
        "qp_total": ("runs", "quasi-periodic"), "qp_with_cap": ("runs", "force cap"),
    },
    "chapters/05_stability": {
        "win_rcrit": ("m", "slipping"), "win_redge": ("m", "slipping"), "f5_n_grid": ("points", "Fig. 5"),
        "f5_n_periodic": ("points", "periodic"), "f5_n_lost": ("points", "lost"),
        "f5_n_turns_round": ("points", "turns round"), "f5_not_held": ("points", "not held"),
    },
    "chapters/06_allocation": {
        "wc_lim": ("", "w_\\varphi"), "wc_lim_kind": ("", "loses stability"),
        "x_not_held_held": ("points", "holds"), "x_not_held_total": ("points", "does not hold"),
        "x_held_failed": ("points", "fails"), "x_held_total": ("points", "does"),
    },
    "chapters/07_percussion": {
        "s_P": ("m", "from C"), "eps": ("m/s", "drag"), "lock": ("m", "locks"), "crit": ("m", "(36)"),
        "rate": ("1/s", "rate"), "n_held": ("points", "held"), "n_grid": ("points", "grid"),
        "n_lost": ("points", "lost"), "n_chaotic": ("points", "chaotic"),
        "lock_ratio": ("times", "lock radius"), "rho": ("", "drag rates' ratio"),
        "fl_held_full": ("points", "full 7-state loop"), "fl_points": ("points", "sampled"),
        "fl_held_zero": ("points", "zero dynamics"),
    },
    "chapters/08_optimal": {
        "b4_max": ("m", "lower bound"), "b4_max_ach": ("m", "motion"), "p4_max": ("m", "paper's law"),
        "p4_ratio": ("times", "least possible"), "bf30c_rms": ("m", "RMS"), "bf30c_rich": ("m", "Richardson"),
        "paper30c_rms": ("m", "RMS"),
        "paper30c_ratio": ("times", "as much"), "opt_periodic": ("settings", "periodic orbit"),
        "opt_n": ("settings", "periodic orbit"), "opt_paper_reached": ("settings", "paper's start"),
        "opt_paper_undecided": ("settings", "undecided"),
        "map_ratio_median": ("times", "median"), "map_FP_max": ("N", "peak force"),
        "mg_cap_cost_rms": ("m", "RMS"), "mg_e2_ratio": ("times", "least possible"),
        "mg_e1_ratio": ("times", "least possible"), "entry_reached": ("settings", "entry"),
        "entry_periods": ("periods", "entry"),
        "em_heading": ("rad", "turned"), "em_pos": ("m", "moved"), "em_m": ("%", "mass"),
        "basin_setting": ("", "measured at"), "mg_wm_cap_0_entry": ("plants", "paper's start"),
        "mg_wm_cap_0_n": ("plants", "wrong and pushed"), "mg_wm_cap_1_entry": ("plants", "with the margin"),
    },
}


#: for each chapter, the bullets of its "What we found" whose status word is glued: glue name -> the
#: report rows (lib.paper.report) the bullet states, which share one status. Every report row of the
#: page is in one bullet (``tests/test_status_words.py``). Chapters 4, 5 and 8 type their words still:
#: Chapter 4's Fig. 4 row reads Chapter 8's computation, which Chapter 4 would then wait for
WHAT_WE_FOUND = {
    "chapters/02_controllability": {
        "found_eq21_rank": ("eq21", "rank"), "found_count": ("count",), "found_thm6_stlc": ("thm6", "stlc"),
        "found_thm7": ("thm7",),
    },
    "chapters/01_model": {"found_eq2_10": ("eq2-4", "eq5-10"), "found_eq6": ("eq6",)},
    "chapters/03_tracking": {
        "found_tracking": ("eq23-24", "eq25-26", "eq27-28", "eq29-30", "eq31", "fig2", "fig3"),
        "found_table": ("table",), "found_wrong_model": ("wrong-model",),
    },
    "chapters/06_allocation": {"found_sec4_open": ("sec4-open",), "found_weight_limit": ("weight-limit",)},
    "chapters/07_percussion": {"found_percussion": ("percussion-circle", "percussion-map")},
}


def what_we_found(page: str) -> dict[str, str]:
    """The status words that head the bullets of ``page``'s "What we found", by glue name
    (:data:`WHAT_WE_FOUND`): each is :func:`lib.paper.report.status` of the bullet's rows, the word
    the report's rows print, capitalised.

    Parameters
    ----------
    page : str
        A chapter's document path, such as ``chapters/02_controllability``.

    Returns
    -------
    dict
        glue name -> status word ("Corrected", "Misapplied", ...).

    Raises
    ------
    ValueError
        If ``page`` has no bullets in :data:`WHAT_WE_FOUND`, or a bullet's rows disagree.
    """
    if page not in WHAT_WE_FOUND:
        raise ValueError(f"page must be one of {sorted(WHAT_WE_FOUND)}, got {page!r}")
    return {name: status(*keys).capitalize() for name, keys in WHAT_WE_FOUND[page].items()}

def findings() -> dict[str, Outcome]:
    """The outcome of each row of :data:`FINDINGS`, by key: its figure of merit (``merit``, the
    unit in the row's label) and the merit's kind (``number()``).

    Returns
    -------
    dict
        key -> the row's :class:`~lib.paper.outcomes.Outcome`.

    Raises
    ------
    AssertionError
        If a row's check decided another status than the one the front page states.
    """
    out = {}
    for key, status in FINDINGS.items():
        o = outcome(key)
        assert o.status == status, (key, o.status, status)
        out[key] = o
    return out


def front_page() -> dict[str, float | Number]:
    """Every number of the front page's findings, by glue name (the keys of ``LABELS["intro"]``).
    A bound, a motion found and an estimate come as a :class:`~lib.machinery.kinds.Number`,
    which the page writes as its kind says.

    Returns
    -------
    dict
        glue name -> value, in the unit :data:`LABELS` gives it.
    """
    f = findings()
    pos, heading, heading_scale = open_loop_gap()
    # the headings differ by round-off (the wrong row does not enter the rotation): printed as the
    # run's accuracy at the heading's scale (Methods, "What a computed number is accurate to")
    heading = within_accuracy(heading, Integration().accuracy(heading_scale))
    gap = mirror_gap()
    free, capped = _angle_sweep(None), _angle_sweep(PAPER_CAP)
    lo, hi = cached(bistable_window, Body(), THETA0)                       # Chapter 5's call
    paper, p_law = fig5_readings(cached(fig5_map, Body())), fig5_readings(cached(percussion_fig5_map, Body()))
    lim = studies.limits_comparison(Body(), Gains())                            # Chapter 8's call
    table = lim["table"]
    cap_only = table[(table.cap == PAPER_CAP) & table.angle_deg.isna()].set_index("law")
    entries = studies.entries(Body(), Gains())                            # Chapter 8's call
    out = {
        "fd_eq6_t": OPEN_LOOP_HORIZON, "fd_eq6_pos": pos, "fd_eq6_heading": heading, "fd_fig3": f["fig3"].merit,
        "fd_mirror_heading": gap[2], "fd_mirror_rate": gap[5], "fd_mirror_pos": float(math.hypot(gap[0], gap[1])),
        "fd_chaos": f["chaos"].number(".2f"), "fd_chaos_n": int((free.regime == "chaotic").sum()),
        "fd_chaos_deg": studies.CHAOS_DEG,
        "fd_chaos_cap_n": int((capped.regime == "chaotic").sum()), "fd_angles": len(SWEEP_DEG),
        "fd_window_lo": lo, "fd_window_hi": hi,
        "fd_grid": paper["grid"], "fd_not_held": paper["not_held"], "fd_lost": paper["lost"],
        "fd_turns": paper["turns_round"], "fd_paper_held": paper["held"], "fd_weight": f["weight-limit"].merit,
        "fd_p_held": p_law["held"], "fd_p_grid": p_law["grid"], "fd_bound": f["cap-bound"].number(".4f"),
        "fd_paper_cap": float(cap_only.max_error["paper"]),
        "fd_opt_cap": best_found(float(cap_only.max_error["optimal"]), ".4f"),
        "fd_e2_R": SECOND_EIGHT[0], "fd_e2_Theta": SECOND_EIGHT[1], "fd_e2_ratio": f["second-eight"].number(".2f"),
        "fd_e1_ratio": upper_bound(float(cap_only.max_error["paper"]) / lim["bound"].max_error, ".2f"),
        "fd_entry_reached": int(entries.reached.sum()), "fd_entry_n": len(entries),
        "fd_entry_periods": ENTRY_PERIODS,
    }
    assert set(out) == set(LABELS["intro"]), set(out) ^ set(LABELS["intro"])
    return out
