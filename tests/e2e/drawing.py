"""Mouse strokes on the page's board, shared by the browser tests and the README's picture (scripts/page_figure.py):
points in board units (1000 × 700), drawn with real mouse events."""

from __future__ import annotations

import numpy as np
from playwright.sync_api import Page


def draw(page: Page, points: list[tuple[float, float]]) -> None:
    """A stroke with mouse events, one move to each point, points in board units (1000 × 700). (Playwright's
    in-between moves, `steps`, add nothing an arc's 30 points lack, and cost: the browser's CPU in the page tests
    101 CPU-s with two steps a point against 89.)"""
    box = page.locator("#board").bounding_box()
    assert box is not None
    at = [(box["x"] + x / 1000 * box["width"], box["y"] + y / 700 * box["height"]) for x, y in points]
    page.mouse.move(*at[0])
    page.mouse.down()
    for p in at[1:]:
        page.mouse.move(*p)
    page.mouse.up()


def arc(cx: float, cy: float, r: float, a0: float, a1: float, n: int = 30) -> list[tuple[float, float]]:
    """n points of a circular arc from angle a0 to a1 (radians), in board units."""
    t = np.linspace(a0, a1, n)
    return list(zip(cx + r * np.cos(t), cy + r * np.sin(t)))
