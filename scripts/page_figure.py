"""docs/figures/page.png: the page as it is, in Chromium at 1440×900 against `curve-vae serve` on the shipped model.

Five curves (four strokes and an in-between taken), the mix of two picked in the list (A and C), the view zoomed in on
them, curve A selected with its control points as handles and its neighbours, the vase revolved.
Needs the page tests' browser (tests/e2e/browser.py: `apt-get install chromium-headless-shell`) and the test extra
(Playwright).

    .venv/bin/python scripts/page_figure.py                # writes docs/figures/page.png
    .venv/bin/python scripts/page_figure.py --out /tmp/p.png
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np
from playwright.sync_api import sync_playwright

from curve_vae.files import atomic_path
from curve_vae.service.live import LiveServer

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from tests.e2e.browser import ARGS, CHROMIUM  # noqa: E402 - the page tests' browser
from tests.e2e.drawing import arc, draw  # noqa: E402 - the page tests' own strokes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "page.png")
    args = parser.parse_args()
    with LiveServer("--model-dir", str(ROOT / "models"), "--providers", "cpu", "--workers", "1", cwd=ROOT) as server:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
            page = browser.new_context(viewport={"width": 1440, "height": 900}).new_page()
            page.goto(server.url + "/")
            bowl = arc(250, 420, 160, 1.05 * np.pi, 1.95 * np.pi)
            t = np.linspace(0, 1, 40)
            draw(page, bowl)  # A, a bowl
            draw(page, list(zip(560 + 330 * t, 330 - 110 * np.sin(np.pi * t) + 60 * t)))  # B, a wave
            draw(page, arc(480, 520, 120, 0.05 * np.pi, 0.95 * np.pi))  # C, a hump
            draw(page, list(zip(150 + 300 * t, 150 + 60 * np.sin(2 * np.pi * t))))  # D, an S
            page.wait_for_function("window.curveVae.items.length === 4 && window.curveVae.recon.every((r) => r)")
            page.wait_for_function("window.curveVae.strip.length === 5")
            page.locator("#strip .thumb").nth(1).click()  # E, an in-between of C and D
            page.wait_for_function("window.curveVae.items.length === 5 && window.curveVae.recon.every((r) => r)")
            for name in ("A", "C"):  # the mix: A and C, picked in the list
                page.locator(f"#curve-list li[data-name='{name}'] .mix-pick").check()
            page.wait_for_function("window.curveVae.result && window.curveVae.result.of.join() === 'A,C'")
            page.locator("#weight").fill("0.35")
            page.wait_for_function("window.curveVae.result.weights[1] === 0.35")
            board = page.locator("#board").bounding_box()
            assert board is not None
            page.mouse.move(board["x"] + 0.42 * board["width"], board["y"] + 0.62 * board["height"])
            page.mouse.wheel(0, -260)  # zoomed in on the mix
            page.wait_for_timeout(300)
            page.click("#vase")
            page.wait_for_function("window.curveVae.vase !== null")
            page.locator("#curve-list li[data-name='A'] .curve-name").click()  # A selected: handles, neighbours
            page.wait_for_function("window.curveVae.neighbours !== null")
            page.mouse.move(0, 0)
            with atomic_path(args.out) as tmp:
                page.screenshot(path=str(tmp) + ".png")
                os.replace(str(tmp) + ".png", tmp)
            browser.close()
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
