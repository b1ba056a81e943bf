"""What the ledger's rows say: the Pareto front of time against image error, the cost slopes over
irradiance size and K, and the recommended settings per error budget."""

from __future__ import annotations

import math

import numpy as np

RECOMMEND_THRESHOLDS = (0.01, 0.02, 0.05)


TRUTH_KEY = "truth_rel_l1_block"  # the first error axis where the path-traced truth was measured
ERROR_LABELS = {
    TRUTH_KEY: "error vs path-traced truth (rel-L1, 4x4 blocks)",
    "image_rel_l1": "image rel-L1 vs exact convolution",
}


def _finite(v) -> bool:
    return isinstance(v, (int, float, np.floating)) and bool(np.isfinite(v))


def usable(r: dict, key: str = "image_rel_l1") -> bool:
    return r.get("status") == "ok" and _finite(r.get("frame_ms_median", math.nan)) and _finite(r.get(key, math.nan))


def error_key(rows: list[dict]) -> str:
    """The truth where every scene of `rows` has it, else the exact convolution."""
    scenes = {r["scene"] for r in rows}
    with_truth = {r["scene"] for r in rows if usable(r, TRUTH_KEY)}
    return TRUTH_KEY if scenes and with_truth == scenes else "image_rel_l1"


def pareto_front(rows: list[dict], key: str = "image_rel_l1") -> list[dict]:
    """Rows not dominated in (frame_ms_median, key): sorted by time, each strictly more accurate
    than every cheaper one."""
    pts = sorted((r for r in rows if usable(r, key)), key=lambda r: (r["frame_ms_median"], r[key]))
    front, best = [], math.inf
    for r in pts:
        if r[key] < best:
            front.append(r)
            best = r[key]
    return front


def log_slope(x, y) -> tuple[float, float, int]:
    """Least-squares slope and intercept of log y against log x (finite positive points only)."""
    x, y = np.asarray(x, np.float64), np.asarray(y, np.float64)
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > 0)
    if ok.sum() < 2 or np.ptp(np.log(x[ok])) == 0:
        return math.nan, math.nan, int(ok.sum())
    b, a = np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)
    return float(b), float(a), int(ok.sum())


def cost_series(rows: list[dict], sweep_like: dict) -> dict:
    """Per scene: the size series (K = kmax, auto taps) and the K series (at k_size, auto taps)."""
    out = {}
    for scene in dict.fromkeys(r["scene"] for r in rows):
        tsd = [
            r
            for r in rows
            if r["scene"] == scene and r["technique"] == "tsd" and r["status"] == "ok" and r["taps"] == "auto"
        ]
        if not tsd:
            continue
        kmax = max(r["K"] for r in tsd)
        by_size = sorted((r for r in tsd if r["K"] == kmax), key=lambda r: r["tsd_size"])
        k_size = sweep_like.get("k_size")
        # the cost of K where texture-space diffusion runs at all (K whose Gaussians all fold into the
        # unblurred term render plain diffuse: a step, not a power law)
        by_k = sorted(
            (r for r in tsd if r["tsd_size"] == k_size and (r.get("blur_levels") or 0) > 0), key=lambda r: r["K"]
        )
        out[scene] = {"size": by_size, "K": by_k, "kmax": kmax, "k_size": k_size}
    return out


def slopes(series: dict) -> dict:
    res = {}
    for scene, s in series.items():
        tex = [r["tsd_size"] ** 2 for r in s["size"]]
        ks = [r["K"] for r in s["K"]]
        lv = [r.get("blur_levels") for r in s["K"]]
        res[scene] = {
            "frame_vs_texels": log_slope(tex, [r["frame_ms_median"] for r in s["size"]]),
            "tsd_vs_texels": log_slope(tex, [r["tsd_ms_median"] for r in s["size"]]),
            "frame_vs_K": log_slope(ks, [r["frame_ms_median"] for r in s["K"]]),
            "tsd_vs_K": log_slope(ks, [r["tsd_ms_median"] for r in s["K"]]),
            "tsd_vs_levels": log_slope(lv, [r["tsd_ms_median"] for r in s["K"]]),
            "sizes": [r["tsd_size"] for r in s["size"]],
            "Ks": ks,
            "levels": lv,
            "kmax": s["kmax"],
            "k_size": s["k_size"],
        }
    return res


def recommendations(rows: list[dict], thresholds=RECOMMEND_THRESHOLDS, key: str = "image_rel_l1") -> list[dict]:
    """For each error budget tau: the cheapest setting (cost: mean over scenes of the median frame
    time) within it in every scene, overall and among tsd settings that blur in every scene. Against
    the exact convolution the budget is absolute (error <= tau); against the truth, where every
    setting keeps the error the techniques share, it counts from each scene's best setting (error <=
    the scene's smallest error + tau)."""
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    by_label: dict[str, dict] = {}
    for r in rows:
        by_label.setdefault(r["setting"], {})[r["scene"]] = r
    floor = {s: 0.0 for s in scenes}
    if key == TRUTH_KEY:
        for s in scenes:
            errs = [r[key] for r in rows if r["scene"] == s and usable(r, key)]
            floor[s] = min(errs) if errs else math.inf
    out = []
    for tau in thresholds:
        ok = []
        for labl, per in by_label.items():
            if len(per) != len(scenes) or not all(usable(r, key) and r[key] <= floor[s] + tau for s, r in per.items()):
                continue
            cost = float(np.mean([r["frame_ms_median"] for r in per.values()]))
            ok.append((cost, labl, per))
        ok.sort(key=lambda t: t[0])
        best = ok[0] if ok else None
        # a tsd setting that blurs nothing in some scene (every Gaussian sub-texel) is the plain frame there
        best_tsd = next(
            (
                t
                for t in ok
                if next(iter(t[2].values()))["technique"] == "tsd"
                and all((r.get("blur_levels") or 0) > 0 for r in t[2].values())
            ),
            None,
        )
        out.append({"threshold": tau, "best": best, "best_tsd": best_tsd, "key": key, "floor": floor})
    return out
