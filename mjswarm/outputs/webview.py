"""Serving recordings with rerun's web viewer, and looking at them in a headless browser.

:func:`serve` runs ``rerun FILE.rrd [VIEW.rbl] --serve-web`` (the web viewer over HTTP
and a gRPC server holding the recording, both on 127.0.0.1) and :func:`web_address`
gives the page to open. :class:`Browser` drives a headless Chromium through the system's
chromedriver (selenium; nothing is downloaded): it opens that page, waits until the
viewer has drawn the data (the page's pixels stop changing) and saves screenshots.
``mjswarm view --web``, the browser test and ``docs/screenshots/make_screenshots.py``
use these; :func:`crop` cuts one view out of a screenshot of the default layout.
"""

from __future__ import annotations

import contextlib
import io
import os
import shutil
import socket
import subprocess
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from urllib.parse import quote

import numpy as np

from mjswarm.errors import MjswarmError
from mjswarm.outputs.recording import check_recording, rerun_command

#: Where Debian puts Chromium and its driver (``apt-get install chromium chromium-driver``).
CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
#: Chromium's switches for a headless run on a closed network with a software GPU.
CHROMIUM_ARGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                 "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync", "--use-angle=swiftshader",
                 "--enable-unsafe-swiftshader", "--disable-dev-shm-usage")


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nobody listens on now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def port_open(port: int, host: str = "127.0.0.1") -> bool:
    """Whether something accepts TCP connections on ``host:port``."""
    with socket.socket() as s:
        s.settimeout(0.5)
        return s.connect_ex((host, port)) == 0


def web_address(web_port: int, grpc_port: int, host: str = "127.0.0.1") -> str:
    """The page that opens the served recording in the web viewer."""
    proxy = quote(f"rerun+http://{host}:{grpc_port}/proxy", safe="")
    return f"http://{host}:{web_port}/?url={proxy}"


def serve_command(files: list[str | Path], web_port: int, grpc_port: int,
                  bind: str = "127.0.0.1") -> list[str]:
    """The ``rerun`` command line that serves ``files`` to the web viewer."""
    return [*rerun_command(), *map(str, files), "--serve-web", "--bind", bind,
            "--web-viewer-port", str(web_port), "--port", str(grpc_port)]


def viewer_env() -> dict[str, str]:
    """The environment for a served viewer: rerun's usage analytics off."""
    return {**os.environ, "RERUN_ANALYTICS": "0"}


@contextlib.contextmanager
def serve(files: list[str | Path], timeout_s: float = 30.0) -> Iterator[str]:
    """Serve ``files`` (``.rrd`` recordings) with rerun's web viewer on
    127.0.0.1 while the context lasts; yields the address to open. Raises
    :class:`MjswarmError` if the server does not listen within ``timeout_s``."""
    web, grpc = free_port(), free_port()
    log = tempfile.TemporaryFile()
    proc = subprocess.Popen(serve_command(files, web, grpc), stdout=log,
                            stderr=subprocess.STDOUT, env=viewer_env())
    try:
        deadline = time.monotonic() + timeout_s
        while not (port_open(web) and port_open(grpc)):
            if proc.poll() is not None or time.monotonic() > deadline:
                log.seek(0)
                tail = log.read().decode(errors="replace").strip().splitlines()[-3:]
                raise MjswarmError(f"rerun's web viewer did not start: {' / '.join(tail)}")
            time.sleep(0.2)
        yield web_address(web, grpc)
    finally:
        stop(proc)
        log.close()


def wait_interruptibly(proc: subprocess.Popen, poll_s: float = 0.1) -> int:
    """Wait for ``proc`` to exit and return its status, waking every ``poll_s`` seconds.

    Not ``proc.wait()``: rerun's SDK runs native threads in this process, and a Ctrl-C
    (SIGINT) that the kernel hands to one of them would not interrupt the main thread
    blocked in ``waitpid``; Python raises :class:`KeyboardInterrupt` only once the main
    thread runs again, which a short sleep guarantees."""
    while proc.poll() is None:
        time.sleep(poll_s)
    return proc.returncode


def stop(proc: subprocess.Popen) -> None:
    """End ``proc`` if it still runs: SIGTERM, then SIGKILL after 10 s."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def serve_web(path: str | Path, port: int | None = None, grpc_port: int | None = None,
              out=None) -> int:
    """``mjswarm view --web``: serve the recording at ``path`` with rerun's web viewer on
    127.0.0.1 (the page on ``port``, default a free one; the data on ``grpc_port``),
    print the address to open, and serve until interrupted (Ctrl-C raises
    :class:`KeyboardInterrupt` after the server is stopped) or until the server exits
    (its exit status). Raises :class:`MjswarmError` if the file is not a recording or a
    port is taken."""
    import sys

    check_recording(path)
    web = free_port() if port is None else port
    grpc = free_port() if grpc_port is None else grpc_port
    for p in (web, grpc):
        if port_open(p):
            raise MjswarmError(f"port {p} on 127.0.0.1 is in use; pick another with --port")
    out = sys.stdout if out is None else out
    proc = subprocess.Popen(serve_command([path], web, grpc), stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, env=viewer_env())
    try:
        deadline = time.monotonic() + 30.0
        while not (port_open(web) and port_open(grpc)):
            if proc.poll() is not None:
                raise MjswarmError(f"rerun's web viewer exited with status {proc.returncode}")
            if time.monotonic() > deadline:
                raise MjswarmError("rerun's web viewer did not start within 30 s")
            time.sleep(0.1)
        print(f"serving {Path(path).name}: open {web_address(web, grpc)}\n"
              f"(from another machine: ssh -L {web}:127.0.0.1:{web} -L "
              f"{grpc}:127.0.0.1:{grpc} HOST, then the same address); Ctrl-C stops",
              file=out, flush=True)
        return wait_interruptibly(proc)
    finally:
        stop(proc)




#: Where the default layout (:func:`mjswarm.outputs.recording._blueprint`, exploration
#: runs) puts its views in the page, as fractions (x0, y0, x1, y1) of its width and height.
LAYOUT_REGIONS = {"arena": (0.0, 0.04, 0.5, 0.73), "map": (0.5, 0.07, 1.0, 0.46),
                  "matrix": (0.5, 0.46, 1.0, 0.73), "events": (0.0, 0.73, 0.5, 0.95),
                  "controller state": (0.5, 0.73, 1.0, 0.95)}


def crop(pixels: np.ndarray, region: str) -> np.ndarray:
    """The part of a screenshot of the default layout where ``region`` (a key of
    :data:`LAYOUT_REGIONS`) is."""
    x0, y0, x1, y1 = LAYOUT_REGIONS[region]
    h, w, _ = pixels.shape
    return pixels[int(y0 * h):int(y1 * h), int(x0 * w):int(x1 * w)]


def save_png(pixels: np.ndarray, path: str | Path) -> None:
    """Write (H, W, 3) uint8 pixels as a PNG."""
    from PIL import Image

    Image.fromarray(pixels).save(path)


def browser_missing() -> str | None:
    """Why no browser test can run here (None: Chromium, chromedriver and selenium are
    all there)."""
    for path in (CHROMIUM, CHROMEDRIVER):
        if not (Path(path).exists() or shutil.which(Path(path).name)):
            return (f"{path} is missing (apt-get install chromium chromium-driver)")
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "selenium is missing (pip install -e '.[dev]')"
    return None


def image(png: bytes) -> np.ndarray:
    """A PNG's pixels as an (H, W, 3) uint8 array."""
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))


class Browser:
    """A headless Chromium of ``width`` x ``height`` pixels (module docstring); use as a
    context manager."""

    def __init__(self, width: int = 1600, height: int = 1000) -> None:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service

        why = browser_missing()
        if why is not None:
            raise MjswarmError(why)
        self._profile = tempfile.TemporaryDirectory(prefix="mjswarm-chromium-")
        options = webdriver.ChromeOptions()
        options.binary_location = CHROMIUM if Path(CHROMIUM).exists() else shutil.which(
            "chromium")
        for arg in CHROMIUM_ARGS:
            options.add_argument(arg)
        options.add_argument(f"--window-size={width},{height}")
        options.add_argument(f"--user-data-dir={self._profile.name}")
        driver = CHROMEDRIVER if Path(CHROMEDRIVER).exists() else shutil.which("chromedriver")
        self.driver = webdriver.Chrome(service=Service(driver), options=options)

    def look(self, address: str, settle_s: float = 4.0, timeout_s: float = 150.0,
             strict: bool = True) -> np.ndarray:
        """Open ``address`` and wait until the page has drawn the data: its pixels vary
        (not a blank page) and have not changed for ``settle_s``. Returns the pixels of
        the last screenshot; after ``timeout_s`` raises :class:`MjswarmError` (``strict``)
        or returns them as they are."""
        self.driver.get(address)
        deadline = time.monotonic() + timeout_s
        last, since = None, time.monotonic()
        from selenium.common.exceptions import TimeoutException

        while True:
            time.sleep(1.0)
            try:
                now = image(self.driver.get_screenshot_as_png())
            except TimeoutException:  # a busy renderer: try again
                continue
            if last is None or now.shape != last.shape or np.abs(
                    now.astype(int) - last).mean() > 0.05 or now.std() < 5:
                last, since = now, time.monotonic()
            elif time.monotonic() - since >= settle_s:
                return now
            if time.monotonic() > deadline:
                if strict or last is None:
                    raise MjswarmError(f"the web viewer did not settle within {timeout_s:g} s")
                return last

    def save(self, path: str | Path) -> np.ndarray:
        """Save a screenshot of the page as a PNG at ``path``; returns its pixels."""
        png = self.driver.get_screenshot_as_png()
        Path(path).write_bytes(png)
        return image(png)

    def close(self) -> None:
        self.driver.quit()
        self._profile.cleanup()

    def __enter__(self) -> Browser:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()


def screenshot(recording: str | Path, out: str | Path, browser: Browser | None = None,
               strict: bool = True) -> np.ndarray:
    """Serve ``recording``, open it in ``browser`` (a new one when None) and save the
    settled page as ``out`` (PNG); returns its pixels. ``strict``: as
    :meth:`Browser.look`."""
    with contextlib.ExitStack() as stack:
        address = stack.enter_context(serve([recording]))
        if browser is None:
            browser = stack.enter_context(Browser())
        browser.look(address, strict=strict)
        return browser.save(out)
