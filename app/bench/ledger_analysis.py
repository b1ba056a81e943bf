"""What the ledger's rows say: the Pareto front of time against image error, the cost slopes over
irradiance size and K, and the recommended settings per error budget."""

from __future__ import annotations

import math

import numpy as np

RECOMMEND_THRESHOLDS = (0.01, 0.02, 0.05)


def usable(r: dict) -> bool:
    return (
        r.get("status") == "ok"
        and np.isfinite(r.get("frame_ms_median", math.nan))
        and np.isfinite(r.get("image_rel_l1", math.nan))
    )


def pareto_front(rows: list[dict]) -> list[dict]:
    """Rows not dominated in (frame_ms_median, image_rel_l1): sorted by time, each strictly more
    accurate than every cheaper one."""
    pts = sorted((r for r in rows if usable(r)), key=lambda r: (r["frame_ms_median"], r["image_rel_l1"]))
    front, best = [], math.inf
    for r in pts:
        if r["image_rel_l1"] < best:
            front.append(r)
            best = r["image_rel_l1"]
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


def recommendations(rows: list[dict], thresholds=RECOMMEND_THRESHOLDS) -> list[dict]:
    """For each error threshold: the cheapest setting whose image rel-L1 is within it in every scene
    (cost: mean over scenes of the median frame time), overall and among tsd settings only."""
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    by_label: dict[str, dict] = {}
    for r in rows:
        by_label.setdefault(r["setting"], {})[r["scene"]] = r
    out = []
    for tau in thresholds:
        ok = []
        for labl, per in by_label.items():
            if len(per) != len(scenes) or not all(usable(r) and r["image_rel_l1"] <= tau for r in per.values()):
                continue
            cost = float(np.mean([r["frame_ms_median"] for r in per.values()]))
            ok.append((cost, labl, per))
        ok.sort(key=lambda t: t[0])
        best = ok[0] if ok else None
        best_tsd = next((t for t in ok if next(iter(t[2].values()))["technique"] == "tsd"), None)
        out.append({"threshold": tau, "best": best, "best_tsd": best_tsd})
    return out
