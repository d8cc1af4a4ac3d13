"""Opens gaitd-view's page in headless Chromium and reports what it shows.

Usage: view_browser.py URL OUT_DIR TIMEOUT_S

Drives Chromium over the DevTools protocol (websockets): loads URL, takes
a screenshot every 1.5 s until the ball is drawn (pixels in the ball's
orange, BALL_MIN of them, in the 3D view: the left 56 % of the page from
below the top bar to 60 % of its height, above the time panel), then
pairs 3 s apart until MOVED_MIN pixels of the 3D view changed within one
(a viewer opened late first catches up) or TIMEOUT_S is up. Writes the
last pair to OUT_DIR (a.png, b.png) and prints one JSON line: the ball's
pixels in each, the pixels of the 3D view that changed between them (the
hand moved), and when the ball and the motion were seen. The page itself
counts the pixels (the screenshot decoded onto a canvas). Exit 2: no
Chromium here (the caller skips).
"""

import asyncio
import base64
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

from collections.abc import Awaitable, Callable
from typing import Any

import websockets

BALL_MIN = 2000
# Changed pixels in 3 s that count as motion.
MOVED_MIN = 300

# Counts, in a PNG screenshot given as base64, the ball's orange pixels of
# the 3D view, and (with a second one) the pixels that differ there.
COUNT = """
async (a, b) => {
  const load = async (s) => {
    const img = new Image();
    img.src = 'data:image/png;base64,' + s;
    await img.decode();
    const c = new OffscreenCanvas(img.width, img.height);
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    return g.getImageData(0, 0, img.width, img.height);
  };
  const A = await load(a);
  const B = b ? await load(b) : null;
  const w = A.width, h = A.height, x1 = Math.floor(0.56 * w), y0 = 60, y1 = Math.floor(0.6 * h);
  let ball = [0, 0], changed = 0;
  for (let y = y0; y < y1; y++) {
    for (let x = 0; x < x1; x++) {
      const i = 4 * (y * w + x);
      [A, B].forEach((I, k) => {
        if (!I) return;
        const r = I.data[i], g = I.data[i + 1], bl = I.data[i + 2];
        if (r > 90 && g > 0.3 * r && g < 0.75 * r && bl < 0.3 * r) ball[k]++;
      });
      if (B) {
        const d = Math.abs(A.data[i] - B.data[i]) + Math.abs(A.data[i + 1] - B.data[i + 1])
          + Math.abs(A.data[i + 2] - B.data[i + 2]);
        if (d > 40) changed++;
      }
    }
  }
  return JSON.stringify({ball_a: ball[0], ball_b: ball[1], changed});
}
"""


def chromium() -> str | None:
    for name in (os.environ.get("GAITD_CHROMIUM"), "chromium", "chromium-browser", "google-chrome"):
        if name and shutil.which(name):
            return shutil.which(name)
    return None


async def run(url: str, out: str, timeout: float) -> dict[str, float]:
    exe = chromium()
    if exe is None:
        print("no chromium on PATH (set GAITD_CHROMIUM)", file=sys.stderr)
        sys.exit(2)
    profile = tempfile.mkdtemp(prefix="gaitd-view-chromium-")
    proc = subprocess.Popen(
        [
            exe,
            "--headless=new",
            "--no-sandbox",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--remote-debugging-port=0",
            f"--user-data-dir={profile}",
            "--window-size=1280,800",
            "about:blank",
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        port_file = os.path.join(profile, "DevToolsActivePort")
        deadline = time.monotonic() + 30
        while not os.path.exists(port_file) or os.path.getsize(port_file) == 0:
            if time.monotonic() > deadline:
                raise RuntimeError("Chromium did not open its DevTools port")
            await asyncio.sleep(0.1)
        port, path = open(port_file).read().split()[:2]
        async with websockets.connect(f"ws://127.0.0.1:{port}{path}", max_size=None) as ws:
            return await drive(ws, url, out, timeout)
    finally:
        proc.kill()
        proc.wait()
        shutil.rmtree(profile, ignore_errors=True)


async def drive(ws: websockets.ClientConnection, url: str, out: str, timeout: float) -> dict[str, float]:
    ids = iter(range(1, 1 << 30))

    async def call(method: str, session: str | None = None, **params: object) -> dict[str, Any]:
        n = next(ids)
        msg: dict[str, object] = {"id": n, "method": method, "params": params}
        if session:
            msg["sessionId"] = session
        await ws.send(json.dumps(msg))
        while True:
            m = json.loads(await ws.recv())
            if m.get("id") == n:
                if "error" in m:
                    raise RuntimeError(f"{method}: {m['error']}")
                result: dict[str, Any] = m["result"]
                return result

    target = await call("Target.createTarget", url="about:blank")
    attached = await call("Target.attachToTarget", targetId=target["targetId"], flatten=True)
    s = str(attached["sessionId"])
    await call("Page.enable", s)
    await call("Page.navigate", s, url=url)

    async def shot() -> str:
        r = await call("Page.captureScreenshot", s, format="png")
        return str(r["data"])

    start = time.monotonic()
    while True:
        await asyncio.sleep(1.5)
        a = await shot()
        seen = await count_in(call, s, a, None)
        if seen["ball_a"] >= BALL_MIN or time.monotonic() - start > timeout:
            break
    waited = time.monotonic() - start
    # A viewer that opens late first catches up with what it missed: pairs
    # of screenshots 3 s apart until one shows motion (or time is up).
    while True:
        await asyncio.sleep(3.0)
        b = await shot()
        result = await count_in(call, s, a, b)
        if result["changed"] >= MOVED_MIN or time.monotonic() - start > timeout:
            break
        a = b
    result["waited_s"] = round(waited, 1)
    result["moved_after_s"] = round(time.monotonic() - start, 1)
    for name, data in (("a.png", a), ("b.png", b)):
        with open(os.path.join(out, name), "wb") as f:
            f.write(base64.b64decode(data))
    return result


async def count_in(
    call: Callable[..., Awaitable[dict[str, Any]]], s: str, a: str, b: str | None
) -> dict[str, float]:
    """The page's counts for screenshot `a` (and `b`)."""
    expr = f"({COUNT})({json.dumps(a)}, {json.dumps(b)})"
    r = await call("Runtime.evaluate", s, expression=expr, awaitPromise=True, returnByValue=True)
    counts: dict[str, float] = json.loads(str(r["result"]["value"]))
    return counts


def main() -> None:
    url, out, timeout = sys.argv[1], sys.argv[2], float(sys.argv[3])
    print(json.dumps(asyncio.run(run(url, out, timeout))))


if __name__ == "__main__":
    main()
