"""What a render is asked to do (beyond the scene itself)."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass
class RenderSettings:
    width: int = 640
    height: int = 640
    shadow_size: int = 2048
    background: tuple[float, float, float] = (0.045, 0.045, 0.05)   # linear
    max_lights: int = 4

    def __post_init__(self) -> None:
        for name in ("width", "height", "shadow_size"):
            v = getattr(self, name)
            if not isinstance(v, int) or v < 1 or v > 16384:
                raise ValueError(f"render setting {name}: expected an integer in [1, 16384], got {v!r}")

    @property
    def size(self) -> tuple[int, int]:
        return self.width, self.height


def parse_size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise ValueError(f"--size: expected WIDTHxHEIGHT such as 640x480, got {text!r}") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise ValueError(f"--size: width and height must be in [1, 16384], got {text!r}")
    return w, h
