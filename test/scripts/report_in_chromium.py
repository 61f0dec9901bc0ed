"""End to end: a small planar run, `curvesfm report` on it, and the page opened in headless
Chromium. Passes when the page records no error (window errors, unhandled rejections,
console.error: its #report-status element; uncaught exceptions in Chromium's console log) and each
figure holds the expected number of plotly traces, and one thumbnail per overlay. Leaves a screenshot, report.png, in WORK_DIR
for a person to look at.

Usage: python3 report_in_chromium.py CURVESFM WORK_DIR
Exit 77 (ctest's skip) without chromium or opencv-doc's graf1.png.
"""
import json
import os
import re
import shutil
import subprocess
import sys
import time

PHOTO = "/usr/share/doc/opencv-doc/examples/data/graf1.png"
EXPECTED_TRACES = {"map": 3, "trajectory": 3, "ate": 2, "timings": 7, "costs": 2}
# Root needs --no-sandbox; swiftshader gives the 3D map its WebGL without a GPU.
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
                  "--virtual-time-budget=20000"]
SKIP = 77


def step(*command):
    start = time.time()
    result = subprocess.run(command, capture_output=True, text=True, timeout=300)
    print("$ %s (%.1f s, exit %d)" % (" ".join(command), time.time() - start, result.returncode))
    if result.returncode != 0:
        sys.exit("failed:\n%s%s" % (result.stdout, result.stderr))
    return result


def report_status(dom):
    match = re.search(r'<pre id="report-status"[^>]*>([^<]*)</pre>', dom)
    if not match or not match.group(1):
        sys.exit("the page did not fill #report-status: its scripts did not run to the end")
    return json.loads(match.group(1).replace("&quot;", '"').replace("&amp;", "&"))


def main(curvesfm, work):
    chromium = shutil.which("chromium")
    if not chromium or not os.path.exists(PHOTO):
        print("skipped: needs chromium and %s (scripts/install-deps.sh)" % PHOTO)
        return SKIP
    shutil.rmtree(work, ignore_errors=True)
    data, out = os.path.join(work, "data"), os.path.join(work, "out")
    step(curvesfm, "synth", "planar", "--image", PHOTO, "--out", data, "--frames", "5",
         "--width", "320", "--height", "240")
    step(curvesfm, "run", "--dataset", data, "--out", out, "--reassociation-rounds", "0",
         "--overlays")
    step(curvesfm, "report", out)
    page = "file://" + os.path.abspath(os.path.join(out, "report.html"))
    # A profile of its own, so that a browser someone else runs on this machine is not reused.
    flags = CHROMIUM_FLAGS + ["--user-data-dir=" + os.path.join(work, "profile")]
    browser = step(chromium, *flags, "--enable-logging=stderr", "--v=0", "--dump-dom", page)
    status = report_status(browser.stdout)
    uncaught = [line for line in browser.stderr.splitlines()
                if "CONSOLE" in line and "Uncaught" in line]
    step(chromium, *flags, "--window-size=1200,2600",
         "--screenshot=" + os.path.join(work, "report.png"), page)
    print("page: %s" % json.dumps(status))
    if status["errors"] or uncaught:
        sys.exit("console errors: %s" % (status["errors"] + uncaught))
    if status["traces"] != EXPECTED_TRACES:
        sys.exit("traces per figure: expected %s, found %s" % (EXPECTED_TRACES, status["traces"]))
    thumbnails = browser.stdout.count('<img src="data:image/png;base64,')
    overlays = len(os.listdir(os.path.join(out, "overlays")))
    if thumbnails != overlays:
        sys.exit("overlay thumbnails: expected %d, found %d" % (overlays, thumbnails))
    print("screenshot: %s" % os.path.join(work, "report.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]) if len(sys.argv) == 3 else __doc__)
