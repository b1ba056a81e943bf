"""A path-traced reference's passes on disk, and what they say about its noise.

A reference is a *series* of independent passes (skinlab/truth/description.py ``render_pass``: pass i
of a series seeded s is the same image whatever else the series holds), so passes rendered by
different runs add up: a killed run resumes from the passes it saved, and a later run with a larger
budget adds to them. Each pass is one file, ``pass-NNNNN.npz`` (its mean image, float32 (H, W, 4), its
samples per pixel and seconds), written to a temporary name beside it and renamed (skinlab/atomic_write.py),
so the store never sees a half-written pass: temporary names start with a dot and are ignored, a file
that does not read back as a finite image of the series' size is discarded with a one-line warning and
rendered again.

From the passes (weights = their samples):

* the image: the samples' mean;
* the halves: the means of the first and the second half of the samples (pass order), whose
  difference is the ledger's noise floor (skinlab/truth/compare.py ``image_error`` between them);
* ``jackknife_groups``: up to ``JACKKNIFE_GROUPS`` consecutive groups of passes of about equal samples,
  for the uncertainty of any error measured against the reference (skinlab/truth/metrics.py);
* ``standard_error``: per pixel, the standard error of the mean from the spread of the passes.
"""

from __future__ import annotations

import json
import re
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skinlab.atomic_write import atomic_path, write_text_atomic

PASS_NAME = re.compile(r"^pass-(\d{5})\.npz$")
JACKKNIFE_GROUPS = 8  # at most this many groups of passes in the delete-a-group jackknife


@dataclass
class Pass:
    index: int
    image: np.ndarray  # (H, W, 4) float32: the pass's mean
    spp: int
    seconds: float


def _warn(text: str) -> None:
    print(f"warning: {text}", file=sys.stderr)


class PassStore:
    """The passes of one series in `folder` (None: kept in memory only), images of `shape` (H, W, 4)."""

    def __init__(self, folder: Path | None, shape: tuple[int, int, int]):
        self.folder = Path(folder) if folder is not None else None
        self.shape = tuple(shape)
        self._memory: dict[int, Pass] = {}

    def path(self, index: int) -> Path:
        if self.folder is None:
            raise ValueError("a pass store kept in memory has no files")
        return self.folder / f"pass-{index:05d}.npz"

    def _read(self, path: Path, index: int) -> Pass | None:
        try:
            with np.load(path, allow_pickle=False) as z:
                img, spp, sec = z["image"], int(z["spp"]), float(z["seconds"])
        except Exception as exc:  # truncated, emptied, garbage: rendered again
            _warn(f"{path}: discarded a damaged reference pass ({type(exc).__name__}); it is rendered again")
            return None
        if img.shape != self.shape or img.dtype != np.float32 or not np.isfinite(img).all() or spp < 1:
            _warn(f"{path}: discarded a reference pass that is not a finite {self.shape} float32 image")
            return None
        return Pass(index, img, spp, sec)

    def load(self) -> list[Pass]:
        """Every valid pass, by index (a damaged file is removed, with a warning)."""
        if self.folder is None:
            return [self._memory[i] for i in sorted(self._memory)]
        if not self.folder.is_dir():
            return []
        out = []
        for p in sorted(self.folder.iterdir()):
            m = PASS_NAME.match(p.name)
            if not m:
                continue  # temporary files (".pass-...") and the series' own json
            got = self._read(p, int(m.group(1)))
            if got is None:
                p.unlink(missing_ok=True)
            else:
                out.append(got)
        return out

    def save(self, p: Pass) -> None:
        if self.folder is None:
            self._memory[p.index] = p
            return
        with atomic_path(self.path(p.index)) as tmp, open(tmp, "wb") as fh:
            np.savez_compressed(fh, image=p.image.astype(np.float32), spp=np.int64(p.spp), seconds=p.seconds)

    def write_info(self, info: dict) -> None:
        if self.folder is not None:
            write_text_atomic(self.folder / "series.json", json.dumps(info, indent=1, default=str))


def _weighted_mean(images: np.ndarray, spp: np.ndarray) -> np.ndarray:
    w = np.asarray(spp, np.float64)
    return (np.tensordot(w, images.astype(np.float64), axes=1) / w.sum()).astype(np.float32)


def split_by_samples(spp, groups: int) -> list[np.ndarray]:
    """Consecutive groups of pass indices whose sample counts are about equal (each non-empty)."""
    spp = np.asarray(spp, np.float64)
    n = len(spp)
    groups = max(1, min(groups, n))
    edges = np.concatenate([[0.0], np.cumsum(spp)])
    targets = edges[-1] * np.arange(1, groups) / groups
    cuts = [0]
    for t in targets:
        c = int(np.argmin(np.abs(edges - t)))
        c = min(max(c, cuts[-1] + 1), n - (groups - len(cuts)))
        cuts.append(c)
    cuts.append(n)
    return [np.arange(cuts[i], cuts[i + 1]) for i in range(groups)]


@dataclass
class PassSet:
    """The passes of a reference, in memory: (P, H, W, 4) float32 images and their samples."""

    images: np.ndarray
    spp: np.ndarray  # (P,) samples per pixel of each pass

    @classmethod
    def of(cls, passes: list[Pass]) -> PassSet:
        return cls(np.stack([p.image for p in passes]), np.array([p.spp for p in passes], np.int64))

    @property
    def count(self) -> int:
        return len(self.spp)

    def mean(self) -> np.ndarray:
        return _weighted_mean(self.images, self.spp)

    def halves(self) -> tuple[np.ndarray, np.ndarray]:
        a, b = split_by_samples(self.spp, 2)
        return _weighted_mean(self.images[a], self.spp[a]), _weighted_mean(self.images[b], self.spp[b])

    def jackknife_groups(self, groups: int = JACKKNIFE_GROUPS) -> list[np.ndarray]:
        """The reference with each group of passes left out in turn (G images, G >= 2): what the
        delete-a-group jackknife measures an error against."""
        parts = split_by_samples(self.spp, groups)
        out = []
        for g in parts:
            keep = np.setdiff1d(np.arange(self.count), g)
            out.append(_weighted_mean(self.images[keep], self.spp[keep]))
        return out

    def standard_error(self) -> np.ndarray:
        """(H, W) standard error of the mean's luminance from the spread of the passes (samples as weights)."""
        from .compare import REC709

        lum = self.images[..., :3].astype(np.float64) @ REC709
        w = self.spp.astype(np.float64)
        m = np.tensordot(w, lum, axes=1) / w.sum()
        # per-sample variance from the passes: var(pass p) = sigma^2 / n_p
        s2 = np.tensordot(w, (lum - m) ** 2, axes=1) / max(self.count - 1, 1)
        return np.sqrt(s2 / w.sum())
