"""What the ledger's rows say: the Pareto front of time against image error, the cost slopes over
irradiance size and K, and the recommended settings per error budget."""

from __future__ import annotations

import math

import numpy as np

from .ledger_row import LedgerRow, finite

RECOMMEND_THRESHOLDS = (0.01, 0.02, 0.05)


TRUTH_KEY = "truth_rel_l1_block"  # the first error axis where the path-traced truth was measured
ERROR_LABELS = {
    TRUTH_KEY: "error vs path-traced truth (rel-L1, 4x4 blocks)",
    "image_rel_l1": "image rel-L1 vs exact convolution",
}


def usable(r: LedgerRow, key: str = "image_rel_l1") -> bool:
    return r.status == "ok" and finite(r.frame_ms_median) and finite(r[key])


def error_key(rows: list[LedgerRow]) -> str:
    """The truth where every scene of `rows` has it, else the exact convolution."""
    scenes = {r.scene for r in rows}
    with_truth = {r.scene for r in rows if usable(r, TRUTH_KEY)}
    return TRUTH_KEY if scenes and with_truth == scenes else "image_rel_l1"


TIE_SIGMAS = 2.0  # two errors differ when their difference is more than this many standard errors


def sigma(r: LedgerRow, key: str) -> float:
    """The uncertainty of r[key] from the truth's noise (0 for a measure without one)."""
    v = r.get(f"{key}_sigma")
    return float(v) if finite(v) else 0.0


def difference_sigma(a: LedgerRow, b: LedgerRow, key: str) -> float:
    """The standard error of a[key] - b[key] from the two uncertainties, sqrt(sigma_a^2 + sigma_b^2):
    conservative (both are measured against the same truth, so part of its noise is shared; the
    per-group values, ``jackknife``, give the paired figure, skinlab/truth/metrics.py paired_sigma, which
    tells deterministic differences of a few hundredths of a per cent apart: real, but not what a ranking
    should turn on)."""
    return math.hypot(sigma(a, key), sigma(b, key))


def told_apart(a: LedgerRow, b: LedgerRow, key: str) -> bool:
    """Whether the errors of two rows differ by more than TIE_SIGMAS times the noise of their difference
    (identical images never do)."""
    return abs(a[key] - b[key]) > TIE_SIGMAS * difference_sigma(a, b, key)


def distinct(rows: list[LedgerRow]) -> list[LedgerRow]:
    """The rows that are not the same image as an earlier row (``same_image_as``)."""
    return [r for r in rows if not r.same_image_as]


def pareto_front(rows: list[LedgerRow], key: str = "image_rel_l1") -> list[LedgerRow]:
    """Rows not dominated in (frame_ms_median, key), sorted by time: each is more accurate than every
    cheaper one by more than the noise (told_apart); a row that is the same image as another is not a
    point of its own."""
    pts = sorted((r for r in distinct(rows) if usable(r, key)), key=lambda r: (r.frame_ms_median, r[key]))
    front: list[LedgerRow] = []
    for r in pts:
        if not front or (r[key] < front[-1][key] and told_apart(r, front[-1], key)):
            front.append(r)
    return front


def best_and_ties(rows: list[LedgerRow], key: str) -> tuple[LedgerRow | None, list[LedgerRow]]:
    """Of one scene's rows: the smallest error, and the other rows the noise cannot tell from it."""
    ok = [r for r in distinct(rows) if usable(r, key)]
    if not ok:
        return None, []
    best = min(ok, key=lambda r: r[key])
    return best, [r for r in ok if r is not best and not told_apart(r, best, key)]


def mark_ties(rows: list[LedgerRow], key: str) -> list[LedgerRow]:
    """The rows (in order) with ``ties_best`` set: "best", "tie" (within the noise of the best) or "", per
    scene among the rows that are not a peer's (peers are drawn beside, never ranked: "")."""
    rank: dict[int, str] = {}
    for scene in dict.fromkeys(r.scene for r in rows):
        best, ties = best_and_ties([r for r in rows if r.scene == scene and not r.peer], key)
        rank.update({id(t): "tie" for t in ties})
        if best is not None:
            rank[id(best)] = "best"
    return [r.but(ties_best=rank.get(id(r), "")) for r in rows]


def log_slope(x, y) -> tuple[float, float, int]:
    """Least-squares slope and intercept of log y against log x (finite positive points only)."""
    x, y = np.asarray(x, np.float64), np.asarray(y, np.float64)
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    if ok.sum() < 2 or np.ptp(np.log(x[ok])) == 0:
        return math.nan, math.nan, int(ok.sum())
    b, a = np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)
    return float(b), float(a), int(ok.sum())


def cost_series(rows: list[LedgerRow], sweep) -> list[dict]:
    """Per scene and per axis a technique declares a cost for (LedgerStyle.cost_axes) and sweeps:
    the rows along that axis (the others at the base), ok, and where the technique declares levels,
    those whose frame blurs at all (a frame that blurs nothing costs a step, not a power law)."""
    from skinlab.render.registry import techniques

    from .sweep import Setting, declared_settings

    out = []
    for scene in dict.fromkeys(r.scene for r in rows):
        by_label = {r.setting: r for r in rows if r.scene == scene and r.status == "ok"}
        for t in techniques():
            decl = t.ledger.sweep.get(sweep.name)
            if decl is None or not t.ledger.cost_axes:
                continue
            base = declared_settings(t.name, sweep)[0]
            for field, (what, power) in t.ledger.cost_axes.items():
                if field not in decl.axes:
                    continue
                pts = []
                for v in decl.axes[field]:
                    st = Setting.of(t.name, **{**dict(base.values), field: v})
                    r = by_label.get(st.label)
                    if r is None or (t.ledger.levels and not (r.blur_levels or 0) > 0) or v is None:
                        continue
                    pts.append((float(v), r))
                pts.sort(key=lambda p: p[0])
                out.append({"scene": scene, "technique": t.name, "field": field, "what": what, "power": power,
                            "points": pts})  # fmt: skip
    return out


def slopes(series: list[dict]) -> list[dict]:
    res = []
    for s in series:
        x = [v ** s["power"] for v, _ in s["points"]]
        res.append(
            {
                **{k: s[k] for k in ("scene", "technique", "field", "what", "power")},
                "values": [v for v, _ in s["points"]],
                "frame": log_slope(x, [r.frame_ms_median for _, r in s["points"]]),
                "own": log_slope(x, [r.technique_ms_median for _, r in s["points"]]),
                "levels": [r.blur_levels for _, r in s["points"]],
            }
        )
    return res


def default_technique() -> str:
    from skinlab.render.settings import RenderSettings

    return RenderSettings(8, 8).technique_name


def recommendations(rows: list[LedgerRow], thresholds=RECOMMEND_THRESHOLDS, key: str = "image_rel_l1") -> list[dict]:
    """For each error budget tau: the cheapest setting (cost: mean over scenes of the median frame
    time) within it in every scene, overall and among the default technique's settings that blur in
    every scene (where it declares levels). Against the exact convolution the budget is absolute
    (error <= tau); against the truth, where every setting keeps the error the techniques share, it
    counts from each scene's best setting, and only differences larger than the noise count: a setting
    qualifies unless its error is above the best's + tau by more than TIE_SIGMAS standard errors of
    the difference."""
    from skinlab.render.registry import get_technique

    scenes = list(dict.fromkeys(r.scene for r in rows))
    by_label: dict[str, dict[str, LedgerRow]] = {}
    for r in rows:
        by_label.setdefault(r.setting, {})[r.scene] = r
    best: dict[str, LedgerRow | None] = {s: None for s in scenes}
    if key == TRUTH_KEY:
        for s in scenes:
            best[s], _ = best_and_ties([r for r in rows if r.scene == s], key)
    floor = {s: (best[s][key] if best[s] is not None else (math.inf if key == TRUTH_KEY else 0.0)) for s in scenes}

    def within(r, s, tau) -> bool:
        if not usable(r, key):
            return False
        b = best[s]
        if b is None:
            return r[key] <= floor[s] + tau
        return r[key] <= floor[s] + tau + TIE_SIGMAS * difference_sigma(r, b, key)

    dflt = default_technique()
    levels = get_technique(dflt).ledger.levels
    out = []
    for tau in thresholds:
        ok = []
        for labl, per in by_label.items():
            if len(per) != len(scenes) or not all(within(r, s, tau) for s, r in per.items()):
                continue
            cost = float(np.mean([r.frame_ms_median for r in per.values()]))
            ok.append((cost, labl, per))
        ok.sort(key=lambda t: t[0])
        top = ok[0] if ok else None
        best_default = next(
            (
                t
                for t in ok
                if next(iter(t[2].values())).technique == dflt
                and (not levels or all((r.blur_levels or 0) > 0 for r in t[2].values()))
            ),
            None,
        )
        out.append(
            {"threshold": tau, "best": top, "best_default": best_default, "default": dflt, "key": key, "floor": floor}
        )
    return out
