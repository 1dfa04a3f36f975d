"""Every clause of the report's extension rows can fail: each check, fed evidence that passes
all its clauses, says ``extended``; fed the same evidence with one clause broken (one angle
group, one run, one parameter in turn), it says ``not reproducible``.

The real evidence passes every clause (``tests/test_report.py``), so it cannot tell a check
from one that drops a clause or lets the last group decide (``ok &= ...`` turned into
``ok = ...``: issue 28). Here the names each check reads its evidence through (the cache and
the library functions imported into :mod:`lib.paper.extensions`) are replaced by fakes, so
nothing is computed. The errata's sub-cases (one k, one coefficient) are in
``tests/test_errata_falsifiable.py``.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from lib.paper import extensions as ext, studies

ITEMS = {i.key: i for i in ext.items()}


def _status(monkeypatch, key, **fakes):
    """The status of extension row ``key`` with the module names ``fakes`` replaced, in the rows'
    module and in lib.paper.studies (the chapters' shared calls, which the rows read)."""
    for name, value in fakes.items():
        mods = [m for m in (ext, studies) if hasattr(m, name)]
        assert mods, name                        # a fake for a name the check no longer reads
        for m in mods:
            monkeypatch.setattr(m, name, value)
    return ITEMS[key].check().status


def _cache(**frames):
    """A stand-in for book_cache.cached: the evidence by the computing function's name."""
    return lambda fn, *args, **kw: frames[fn.__name__]


def _same(a, b) -> bool:
    """Equal arguments: arrays element by element, sequences item by item, else ``==``."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.shape(a) == np.shape(b) and bool(np.all(np.asarray(a) == np.asarray(b)))
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    return type(a) is type(b) and a == b


def _asks(value, *expected):
    """A fake that returns ``value`` when called with exactly the arguments ``expected``."""
    def fake(*args):
        assert _same(args, expected), f"called with {args!r}, expected {expected!r}"
        return value
    return fake


# ------------------------------------------------------------------ limit-lyapunov: per angle group

def _horizons(changes=(0.17, 0.17), ratios=(49.0, 49.0)):
    """Chapter 4's convergence frame for 30 and 45 deg: the exponent at 120 periods and at the
    longest horizon differ by ``changes`` standard errors (at 120), and the longest is
    ``ratios`` standard errors above zero."""
    rows = []
    for deg, change, ratio in zip((30.0, 45.0), changes, ratios):
        se = 0.01
        long_ = ratio * 0.001
        rows += [dict(angle_deg=deg, horizon=120, lyapunov=long_ + change * se, stderr=se),
                 dict(angle_deg=deg, horizon=1920, lyapunov=long_, stderr=0.001)]
    return pd.DataFrame(rows)


@pytest.mark.parametrize("changes, ratios, status", [
    ((0.17, 0.17), (49, 49), "extended"),
    ((3.1, 0.17), (49, 49), "not reproducible"),       # the first group not converged (3 SE, Chapter 4's margin)
    ((0.17, 3.1), (49, 49), "not reproducible"),       # the last group not converged
    ((2.9, 1.3), (49, 49), "extended"),                # within the margin
    ((0.17, 0.17), (3, 49), "not reproducible"),       # the first group's exponent within 6 SE
    ((0.17, 0.17), (49, 3), "not reproducible"),       # the last group's
])
def test_limit_lyapunov_row_needs_every_angle_group_converged_and_positive(monkeypatch, changes, ratios, status):
    assert _status(monkeypatch, "limit-lyapunov", cached=_cache(lyapunov_horizons=_horizons(changes, ratios))) \
        == status


# ------------------------------------------------------------------ limit-mirror: each clause

def _mirror_frame(paper=("A", False, 2.56), mirror="A'"):
    """start_attractors' frame: Chapter 4's 12 heading offsets, then the mirrored start."""
    rows = [dict(attractor="A", symmetric=False, mirror_gap=2.56) for _ in range(12)]
    rows[6] = dict(attractor=paper[0], symmetric=paper[1], mirror_gap=paper[2])     # offset 0
    rows.append(dict(attractor=mirror, symmetric=False, mirror_gap=2.56))
    return pd.DataFrame(rows)


@pytest.mark.parametrize("paper, mirror, defect, status", [
    (("A", False, 2.56), "A'", 3e-14, "extended"),
    (("A'", False, 2.56), "A'", 3e-14, "not reproducible"),    # the paper's start reaches the other one
    (("A", True, 2.56), "A'", 3e-14, "not reproducible"),      # its orbit is its own mirror
    (("A", None, 2.56), "A'", 3e-14, "not reproducible"),      # symmetry not decided
    (("A", False, 0.5), "A'", 3e-14, "not reproducible"),      # the mirror orbit too near
    (("A", False, 2.56), "A", 3e-14, "not reproducible"),      # the mirrored start reaches A
    (("A", False, 2.56), "A'", 1e-6, "not reproducible"),      # the loop not symmetric
])
def test_limit_mirror_row_fails_with_each_of_its_clauses(monkeypatch, paper, mirror, defect, status):
    # every call asks for Chapter 4's case: the eight from the paper's start, a 90 deg limit, no
    # cap, its 12 heading offsets and the mirrored start, a defect over 4 periods
    body, gains, ref = ext.Body(), ext.Gains(), ext.eight(2.0, math.pi / 4)
    s0 = np.concatenate([ext.PAPER_Z0, ext.PAPER_DZ0])
    case = (body, gains, ref, math.radians(90), None)
    offsets = np.radians(np.arange(-180, 180, 30))
    starts = np.vstack([np.arange(72.0).reshape(12, 6), -np.ones((1, 6))])

    def frames(fn, *args):
        assert fn.__name__ == "start_attractors" and _same(args, case + (starts,))
        return _mirror_frame(paper, mirror)

    got = _status(monkeypatch, "limit-mirror", cached=frames,
                  heading_offset_starts=_asks(starts[:12], offsets),
                  mirrored_start=_asks(starts[12:], *case, s0),
                  mirror_defect=_asks(np.array([0.0, defect]), *case, s0, 4),
                  mirror_gap=lambda: np.array([1.0, 1.0, 2.0, 0.1, 0.1, 0.5]))
    assert got == status


# ------------------------------------------------------------------ wrong-model: each run, each clause

def _study(bad_run=None, column=None, verdicts=0, top=("m", "c"), gap=2e-6):
    runs = pd.DataFrame(dict(regime=["periodic"] * 4, lost=[False] * 4, position_lost=[False] * 4,
                             pos_max=[0.1, 0.2, 0.3, 0.4], pos_linear=[0.1, 0.2, 0.3, 0.4 + gap]))
    if bad_run is not None:
        runs.loc[bad_run, column] = "chaotic" if column == "regime" else True
    rank = pd.DataFrame(dict(parameter=[*top, "I", "a"], verdicts=[verdicts, 0, 0, 0]))
    return dict(map=runs, influence=rank)


@pytest.mark.parametrize("study, status", [
    (dict(), "extended"),
    (dict(bad_run=0, column="regime"), "not reproducible"),
    (dict(bad_run=3, column="regime"), "not reproducible"),
    (dict(bad_run=2, column="lost"), "not reproducible"),
    (dict(bad_run=3, column="position_lost"), "not reproducible"),
    (dict(verdicts=1), "not reproducible"),
    (dict(top=("m", "I")), "not reproducible"),
    (dict(gap=2e-4), "not reproducible"),
], ids=["all", "first-run-regime", "last-run-regime", "lost", "position-lost", "verdicts", "top", "gap"])
def test_wrong_model_row_fails_with_each_run_and_each_clause(monkeypatch, study, status):
    assert _status(monkeypatch, "wrong-model", cached=_cache(mismatch_study=_study(**study))) == status


# ------------------------------------------------------------------ slow-eights: each clause

def _fig5(bad=None):
    f = pd.DataFrame(dict(R=[1.0, 2.0, 1.0, 2.0, 3.0], Theta=[0.05, 0.05, 0.2, 0.3, 0.8],
                          regime=["periodic"] * 4 + ["chaotic"], period=[1, 1, 1, 1, 0],
                          lost=[False] * 5, range=[0.5, 0.4, 0.6, 0.7, np.nan]))
    if bad is not None:
        col, row, value = bad
        f.loc[row, col] = value
    return f


def _prediction(err=0.029, slips=False):
    def predict(body, R, Theta):
        # the band's slowest rate, at its points in the map's order
        assert list(R) == [1.0, 2.0] and list(Theta) == [0.05, 0.05]
        return SimpleNamespace(corrected_range=np.array([0.5, 0.4 + err]), corrected_slips=np.array([False, slips]))
    return predict


@pytest.mark.parametrize("bad, err, slips, status", [
    (None, 0.029, False, "extended"),
    (None, 0.06, False, "not reproducible"),                    # the prediction misses the range
    (None, 0.029, True, "not reproducible"),                    # the prediction slips
    (("regime", 3, "quasiperiodic"), 0.029, False, "not reproducible"),   # one point of the band
    (("period", 2, 2), 0.029, False, "not reproducible"),
    (("lost", 0, True), 0.029, False, "not reproducible"),
    (("regime", 4, "quasiperiodic"), 0.029, False, "extended"),           # outside the band: no matter
])
def test_slow_eights_row_fails_with_each_clause_and_each_point_of_the_band(monkeypatch, bad, err, slips, status):
    assert _status(monkeypatch, "slow-eights", cached=_cache(fig5_map=_fig5(bad)),
                   slow_eight_prediction=_prediction(err, slips)) == status


# ------------------------------------------------------------------ window and weight-limit

@pytest.mark.parametrize("width, th, gap, status", [
    (0.0045, 0.70, 1e-9, "extended"),
    (0.0, 0.70, 1e-9, "not reproducible"),          # no window
    (0.02, 0.70, 1e-9, "not reproducible"),         # too wide
    (0.0045, 0.80, 1e-9, "not reproducible"),       # closes above the paper's rate
    (0.0045, 0.70, 1e-3, "not reproducible"),       # not the pendulum's threshold
])
def test_window_row_fails_with_each_clause(monkeypatch, width, th, gap, status):
    body = ext.Body()
    threshold = math.sqrt(body.c_phi / (body.I * th)) / (1.0 + gap)

    def window(body_, theta):
        assert body_ == body and theta == math.pi / 4              # the paper's rate
        return 1.0, 1.0 + width

    assert _status(monkeypatch, "window", cached=lambda fn, *a, **kw: fn(*a, **kw),     # no build cache
                   bistable_window=window,
                   window_closing_rate=lambda body: th, torque_pendulum_threshold=lambda: threshold) == status


@pytest.mark.parametrize("w, below, above, status", [
    (3.13, -1e-3, 1e-3, "extended"),
    (3.13, 1e-3, 1e-3, "not reproducible"),         # unstable already below the limit
    (3.13, -1e-3, -1e-3, "not reproducible"),       # still stable above it
])
def test_weight_limit_row_fails_with_each_clause(monkeypatch, w, below, above, status):
    def steady(body, gains, R, Theta, weights):
        return SimpleNamespace(eigenvalues=np.array([below if weights[2] < w else above, -1.0]))

    assert _status(monkeypatch, "weight-limit",
                   circle_weight_limit=lambda *a: SimpleNamespace(w_phi=w, kind="complex pair"),
                   circle_steady_state=steady) == status


# ------------------------------------------------------------------ percussion: the circle and the map

@pytest.mark.parametrize("radius_gap, lock, rate, status", [
    (0.0, None, None, "extended"),                 # the real closed forms
    (1e-6, None, None, "not reproducible"),        # C's closed-form circle is not the paper's R
    (0.0, 1.01, None, "not reproducible"),         # the lock radius just above the paper's (36)
    (0.0, None, 0.5, "not reproducible"),          # the heading's rate not negative
])
def test_percussion_circle_row_fails_with_each_clause(monkeypatch, radius_gap, lock, rate, status):
    # the closed forms themselves (instant), each clause broken by a wrapper; the check must ask
    # Chapter 7's lib.percussion.claims.paper_circle_of_p about the paper's circle (R = 2 m,
    # Theta = pi/4 rad/s): another rate is refused here, another radius also by the first case
    real_circle, real_lock = ext.paper_circle_of_p, ext.circle_lock_radius

    def circle_of_p(*args):
        assert _same(args, (ext.Body(), 2.0, math.pi / 4)), args
        R_P, st = real_circle(*args)
        return R_P, SimpleNamespace(radius_C=st.radius_C * (1 + radius_gap), rate=st.rate if rate is None else rate)

    def lock_radius(body, th):
        return real_lock(body, th) if lock is None else lock * ext.circle_critical_radius(body, th)

    assert _status(monkeypatch, "percussion-circle", paper_circle_of_p=circle_of_p,
                   circle_lock_radius=lock_radius) == status


def _full_loop(n_held=4):
    """Chapter 7's full-loop verdicts on a 4-point sample, ``n_held`` of them held."""
    return pd.DataFrame({"held": [True] * n_held + [False] * (4 - n_held)})


@pytest.mark.parametrize("regime, lost, status", [
    ("periodic", False, "extended"),
    ("chaotic", False, "not reproducible"),        # one chaotic point
    ("periodic", True, "not reproducible"),        # one point lost
    ("transient", False, "not reproducible"),      # one point not held
])
def test_percussion_map_row_fails_with_one_point_not_held(monkeypatch, regime, lost, status):
    fr = pd.DataFrame({"regime": ["periodic"] * 9 + [regime], "lost": [False] * 9 + [lost]})
    paper = pd.DataFrame({"regime": ["periodic"] * 7 + ["chaotic"] * 3, "lost": False, "turns_round": False})
    got = _status(monkeypatch, "percussion-map",
                  cached=_cache(percussion_fig5_map=fr, fig5_map=paper, full_loop_verdicts=_full_loop()))
    assert got == status


@pytest.mark.parametrize("n_held", [4, 3])
def test_percussion_map_row_states_the_full_loop_sample_without_deciding_on_it(monkeypatch, n_held):
    # the full loop is reported in the note, not a clause: the status follows the zero dynamics
    fr = pd.DataFrame({"regime": ["periodic"] * 10, "lost": False})
    paper = pd.DataFrame({"regime": ["periodic"] * 7 + ["chaotic"] * 3, "lost": False, "turns_round": False})
    seen = []

    def cache(fn, *args, **kw):
        if fn.__name__ == "full_loop_verdicts":
            seen.append(args)
            return _full_loop(n_held)
        return {"percussion_fig5_map": fr, "fig5_map": paper}[fn.__name__]

    monkeypatch.setattr(ext, "cached", cache)
    monkeypatch.setattr(studies, "cached", cache)
    out = ITEMS["percussion-map"].check()
    assert out.status == "extended"
    assert f"holds the heading at {n_held} of its 4 points" in out.note
    # Chapter 7's call, argument for argument, so the build's cache is shared
    R_s, Th_s, _ = studies.grid_sample(10)
    assert len(seen) == 1 and _same(seen[0], (ext.Body(), ext.Gains(), R_s, Th_s))


@pytest.mark.parametrize("lost, not_held, undecided, status", [
    (36, 277, 0, "extended"), (36, 277, 50, "extended"),
    (0, 277, 0, "not reproducible"),            # the heading lost nowhere
    (36, 1000, 0, "not reproducible"),          # nothing held
    (36, 277, 51, "not reproducible"),          # more than 5 % undecided
])
def test_fig5_map_row_needs_a_map_partly_lost_and_decided(monkeypatch, lost, not_held, undecided, status):
    n = 1000
    regime = np.array(["periodic"] * n, dtype=object)
    regime[:not_held] = "chaotic"
    regime[not_held - undecided:not_held] = "undecided"
    fr = pd.DataFrame({"regime": regime, "lost": np.arange(n) < lost, "turns_round": np.arange(n) < 300,
                       "periods": 120, "drift_periods": 300})
    assert _status(monkeypatch, "fig5-map", cached=_cache(fig5_map=fr)) == status


def test_drift_tests_chance_of_calling_a_point_lost_is_students_t_over_the_longer_runs_blocks():
    # a drift over 300 periods, 1200 over the longer run: 100 blocks of 12 periods in 25 batches of 48
    # (statistics.batch_grouping), 24 degrees of freedom; a drift over 72 periods: 288, 6 batches of 48
    from scipy import stats

    fr = pd.DataFrame({"regime": ["periodic", "slipping", "chaotic", "chaotic", "undecided"], "periods": 120,
                       "drift_periods": [0, 0, 300, 300, 300]})
    tested, chance = ext.lost_false_positives(fr)
    # accuracy: scipy's t tail, the same call, summed over three points (rounding only)
    assert tested == 3 and chance == pytest.approx(3 * 2 * stats.t.sf(3.0, 24), rel=1e-12)
    assert 0.018 < chance < 0.020          # reason: 3 x 0.0062, far above the normal tail 3 x 0.0027
    _, short = ext.lost_false_positives(fr.assign(drift_periods=72))
    assert short == pytest.approx(3 * 2 * stats.t.sf(3.0, 5), rel=1e-12)  # accuracy: as above


def test_fig5_readings_count_each_reading_from_its_own_column():
    fr = pd.DataFrame({"regime": ["periodic", "periodic", "slipping", "chaotic", "undecided"],
                       "lost": [False, False, True, False, False], "turns_round": [False, True, True, True, False]})
    assert ext.fig5_readings(fr) == {"grid": 5, "lost": 1, "turns_round": 3, "not_held": 3, "held": 2,
                                     "undecided": 1}


# ------------------------------------------------------------------ Chapter 8's rows

_SETTINGS = [(None, 4.0), (30, None), (30, 4.0)]


def _ch8_study(*, bound=0.1, achieved=0.1002, gap=1e-9, law_max=None, paper_rms=None, motion_rms=None,
           regimes=None, optimal_rms=None):
    """Chapter 8's study with every clause met, or broken where an argument says so."""
    rows = []
    law_max = law_max or {}
    for i, (a, c) in enumerate(_SETTINGS):
        base = dict(setting=f"s{i}", angle_deg=np.nan if a is None else float(a), cap=np.nan if c is None else c)
        rows.append(dict(base, law="paper", regime="periodic", max_error=law_max.get(i, 0.4),
                         rms_error=(paper_rms or {}).get(i, 0.3), floquet=np.nan, paper_start_reached=np.nan))
        rows.append(dict(base, law="optimal", regime=(regimes or {}).get(i, "periodic"), max_error=0.15,
                         rms_error=(optimal_rms or {}).get(i, 0.05), floquet=0.1, floquet_error=0.01,
                         paper_start_reached=True))
    motions = {k: SimpleNamespace(rms_error=(motion_rms or {}).get(i, 0.05)) for i, k in enumerate(_SETTINGS)}
    b = SimpleNamespace(max_error=bound, max_error_achieved=achieved, gap=gap)
    return dict(table=pd.DataFrame(rows), motions=motions, bound=b)


def _cached_study(st):
    def fake(fn, *args):
        assert fn is studies.limits_study and _same(args, (ext.Body(), ext.Gains(), ext.R0, ext.THETA0)), args
        return st
    return fake


@pytest.mark.parametrize("kw, status", [
    ({}, "extended"),
    ({"bound": 0.0, "achieved": 0.0}, "not reproducible"),            # no bound
    ({"achieved": 0.1 * 1.02}, "not reproducible"),                   # bracket 2 % wide
    ({"gap": 1e-5}, "not reproducible"),                              # solver not converged
    ({"law_max": {0: 0.09}}, "not reproducible"),                     # a law below the bound
    ({"law_max": {2: 0.09}}, "not reproducible"),                     # ... at another capped setting
    ({"law_max": {1: 0.09}}, "extended"),                             # no cap there: not compared
])
def test_cap_bound_row_fails_with_each_clause(monkeypatch, kw, status):
    assert _status(monkeypatch, "cap-bound", cached=_cached_study(_ch8_study(**kw))) == status


@pytest.mark.parametrize("kw, ret, status", [
    ({}, 1e-9, "extended"),
    ({}, 1e-5, "not reproducible"),                                   # a motion not reproduced by integration
    ({"motion_rms": {2: 0.31}}, 1e-9, "not reproducible"),            # no better than the paper's law
    ({"motion_rms": {0: 0.31}}, 1e-9, "not reproducible"),            # ... at the cap alone
    ({"motion_rms": {1: 0.31}}, 1e-9, "extended"),                    # uncapped: not claimed
])
def test_angle_optimum_row_fails_with_each_clause(monkeypatch, kw, ret, status):
    assert _status(monkeypatch, "angle-optimum", cached=_cached_study(_ch8_study(**kw)),
                   verify_motion=lambda body, m: ret,
                   motion_meshes=lambda body, gains: {"frame": _ch8_meshes(ret=ret, **kw)}) == status


def _ch8_meshes(*, ret, motion_rms=None):
    """Chapter 8's mesh study of the angle-limited settings: a coarser mesh that meets every clause,
    and the finest, which the row reads, met or broken as ``motion_rms`` and ``ret`` say."""
    rows = []
    for i, (a, c) in enumerate(_SETTINGS):
        if a is not None:
            base = dict(setting=f"s{i}", angle_deg=a, cap=np.nan if c is None else c)
            rows.append(dict(base, nodes=160, rms_integrated=0.06, return_position=1e-9))
            rows.append(dict(base, nodes=320, rms_integrated=(motion_rms or {}).get(i, 0.05), return_position=ret))
    return pd.DataFrame(rows)


@pytest.mark.parametrize("kw, status", [
    ({}, "extended"),
    ({"regimes": {1: "undecided"}}, "not reproducible"),              # one setting not periodic
    ({"optimal_rms": {2: 0.06}}, "not reproducible"),                 # the loop 1 cm off its plan
])
def test_optimal_tracker_row_fails_with_each_clause(monkeypatch, kw, status):
    assert _status(monkeypatch, "optimal-tracker", cached=_cached_study(_ch8_study(**kw))) == status


# ------------------------------------------------------------------ issue 51: margin, wrong plant, second eight
_MARGIN_SETTINGS = ("4 N", "30 deg + 4 N")


def _issue51(*, regimes=None, mu_on=None, cost=None, wrong_regime=None, worst=0.33, need=9.46, ratio=3.0,
             trk_regime="periodic", trk_rms=0.3356):
    """Chapter 8's issue-51 study with every clause met, or broken where an argument says so."""
    margin = pd.DataFrame([dict(setting=s, margin=m, regime=(regimes or {}).get((s, m), "periodic"),
                                floquet=(mu_on or {}).get(s, 0.001) if m else 0.03, floquet_error=0.001,
                                rms_error=0.1 + ((cost or {}).get(s, 0.07) if m else 0.0),
                                starts_reached=3, starts=7, plan_cap=3.6 if m else 4.0)
                           for s in _MARGIN_SETTINGS for m in (False, True)])
    wrong = pd.DataFrame([dict(setting=s, margin=m, parameter=p, regime="periodic", rms_error=0.2,
                               paper_start_reached=True, entry_reached=False)
                          for s in _MARGIN_SETTINGS for m in (False, True) for p in ("m", "c")])
    wrong.loc[0, "rms_error"] = worst
    for i, r in (wrong_regime or {}).items():
        wrong.loc[i, "regime"] = r
    b = SimpleNamespace(max_error=0.462, rms_error=0.3346, rms_error_achieved=0.3347)
    second = dict(R=1.5, Theta=1.2, need=need, bound=b, paper=dict(max_error=ratio * 0.462),
                  tracked=dict(regime=trk_regime, rms_error=trk_rms, max_error=0.476))
    return dict(margin=margin, wrong=wrong, second=second)


def _cached_issue51(st):
    def fake(fn, *args):
        assert fn is ext.margins.issue_study and _same(args, (ext.Body(), ext.Gains(), ext.R0, ext.THETA0)), args
        return st
    return fake


@pytest.mark.parametrize("kw, status", [
    ({}, "extended"),
    ({"regimes": {("30 deg + 4 N", True): "undecided"}}, "not reproducible"),   # one loop not periodic
    ({"mu_on": {"4 N": 0.05}}, "not reproducible"),                          # the margin contracts slower
    ({"mu_on": {"30 deg + 4 N": 0.05}}, "not reproducible"),                 # ... at the other setting
    ({"cost": {"30 deg + 4 N": -0.01}}, "not reproducible"),                 # the margin costs nothing
])
def test_margin_row_fails_with_each_clause(monkeypatch, kw, status):
    assert _status(monkeypatch, "tracker-margin", cached=_cached_issue51(_issue51(**kw))) == status


@pytest.mark.parametrize("kw, status", [
    ({}, "extended"),
    ({"wrong_regime": {5: "undecided"}}, "not reproducible"),                # one plant not periodic
    ({"worst": 0.6}, "not reproducible"),                                   # an error over half a metre
    ({"worst": np.nan}, "not reproducible"),                                # no orbit to measure
])
def test_tracker_wrong_model_row_fails_with_each_clause(monkeypatch, kw, status):
    assert _status(monkeypatch, "tracker-wrong-model", cached=_cached_issue51(_issue51(**kw))) == status


@pytest.mark.parametrize("kw, status", [
    ({}, "extended"),
    ({"need": 3.9}, "not reproducible"),                                    # the cap does not bind
    ({"ratio": 0.9}, "not reproducible"),                                   # the law below the bound
    ({"trk_regime": "undecided"}, "not reproducible"),                      # the tracker not periodic
    ({"trk_rms": 0.3340}, "not reproducible"),                              # the tracker below the bound
    ({"trk_rms": 0.3400}, "not reproducible"),                              # over 1 % above the bracket
])
def test_second_eight_row_fails_with_each_clause(monkeypatch, kw, status):
    assert _status(monkeypatch, "second-eight", cached=_cached_issue51(_issue51(**kw))) == status


def _entries(n=9, unreached=(), unsettled_regime=(), gap=6e-6):
    return pd.DataFrame([dict(setting=f"s{i}", regime="undecided" if i in unsettled_regime else "periodic",
                              reached=i not in unreached, settled=True, end_position=gap) for i in range(n)],
                        columns=["setting", "regime", "reached", "settled", "end_position"])


@pytest.mark.parametrize("kw, status", [
    ({}, "extended"),
    ({"unreached": (8,)}, "not reproducible"),                 # one setting not reached from the entry
    ({"unsettled_regime": (0,)}, "not reproducible"),          # one loop not periodic
    ({"gap": 2e-4}, "not reproducible"),                       # the entry ends off the motion
    ({"n": 0}, "not reproducible"),                            # no setting at all
])
def test_entry_row_fails_with_each_clause(monkeypatch, kw, status):
    assert _status(monkeypatch, "entry", entries=lambda body, gains: _entries(**kw)) == status


def test_every_extension_row_has_a_falsifying_test():
    tested = {"limit-lyapunov", "limit-mirror", "wrong-model", "slow-eights", "window", "weight-limit",
              "percussion-circle", "percussion-map", "cap-bound", "angle-optimum", "optimal-tracker", "fig5-map",
              "tracker-margin", "tracker-wrong-model", "second-eight", "entry"}
    assert set(ITEMS) == tested
