"""The browser the page's tests and pictures drive: Debian's chromium-headless-shell, through Playwright's Python
client (no browser download; `apt-get install chromium-headless-shell`, done by .ci/run).

The headless shell is Chromium's engine without the browser around it, the build Playwright itself runs headless
tests in. It opens a page in a fifth of the CPU the full browser's `--headless=new` takes (0.25 against 1.2-1.5
CPU-s for a new context loading the page, here; a stroke costs the same): the page's ~60 tests each open one. Where only
Debian's `chromium` is installed, that runs them, headless.
"""

from __future__ import annotations

import shutil

SHELL = shutil.which("chromium-headless-shell")
#: The browser's executable: the headless shell, else the full browser; None where neither is installed.
CHROMIUM = SHELL or shutil.which("chromium")
#: No sandbox (CI runs as root), no GPU, nothing fetched in the background.
ARGS = [
    *([] if SHELL else ["--headless=new"]),
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
