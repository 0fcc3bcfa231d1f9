#!/usr/bin/env python3
"""test_pages.py - the animation pages of eom-run in a real browser
(headless Chromium from Debian; docs/run.md, "The animation page").

For every shipped model: eom-run MODEL --out writes the CSV and
write_page (eom_run_animation, as eom-run --plots calls it, without
gnuplot's plots; the double pendulum goes through --plots itself) the
page NAME-animation.html;
the page loads with no console error, its frame count and frame times are
the CSV's rows kept by the documented budget. For the double pendulum and
the cart-pole, the pixel centre of the red bob in a screenshot at the first
and the last frame is where the CSV's coordinates put it (worked out here
from the angles, not read from the page) to 2 px; #t=S moves the slider to
the last frame at or before S; a spatial model's WebGL view shows its red
marker; a 10,000-row run of the closed chain keeps at most 2000 frames and
its page stays under 5 MB.

usage: test_pages.py EOM_RUN WRITE_PAGE MODELS_DIR
Exit 77 (skipped) with a message when Chromium is missing. Only the
Python standard library: the PNG is decoded here with zlib.
"""
import csv
import json
import math
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

FAILS = []
CHECKS = [0]
TIMEOUT = 120  # seconds per browser run; a loaded 2-core machine needs ~5


def check(cond, what):
    CHECKS[0] += 1
    if not cond:
        FAILS.append(what)
        print("FAIL:", what, file=sys.stderr)


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def browser(exe, url, extra, workdir):
    """Run headless Chromium once; its stdout and stderr."""
    cmd = [exe, "--headless", "--no-sandbox", "--no-first-run",
           "--disable-gpu-sandbox", "--use-angle=swiftshader",
           "--enable-unsafe-swiftshader", "--hide-scrollbars",
           "--window-size=860,960", "--enable-logging=stderr", "--v=0",
           "--user-data-dir=" + os.path.join(workdir, "profile")] + extra
    r = subprocess.run(cmd + [url], capture_output=True, text=True,
                       timeout=TIMEOUT, cwd=workdir)
    return r.stdout, r.stderr


def status_of(exe, page, frag, workdir):
    """The page's #status object after load, and its console errors."""
    out, err = browser(exe, "file://" + page + frag, ["--dump-dom"],
                       workdir)
    m = re.search(r'<pre id="status">([^<]*)</pre>', out)
    errors = [line for line in err.splitlines()
              if "CONSOLE" in line and
              ("Uncaught" in line or "rror" in line)]
    if not m:
        return None, errors + ["no status in the page"]
    return json.loads(m.group(1).replace("&quot;", '"')), errors


def page_data(page):
    """The JSON object of the page (const D)."""
    with open(page, encoding="utf-8") as f:
        text = f.read()
    start = text.index("const D = ") + len("const D = ")
    end = text.index(";\nconst status")
    return json.loads(text[start:end])


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    head = rows[0]
    return {name: [float(r[k]) for r in rows[1:]]
            for k, name in enumerate(head)}


def kept_rows(nrows, nv):
    """docs/run.md: at most 2000 frames and 300000 drawn values; every
    k-th row from the first (the smallest k that fits), and the last."""
    budget = max(2, min(2000, 300000 // max(nv, 1)))
    k = 1
    while True:
        rows = list(range(0, nrows, k))
        if rows[-1] != nrows - 1:
            rows.append(nrows - 1)
        if len(rows) <= budget:
            return rows
        k += 1


def png_pixels(path):
    """(width, height, rows of (r, g, b)) of an 8-bit RGB or RGBA PNG."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat = 8, b""
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB",
                                                                body)
            assert depth == 8 and ctype in (2, 6) and interlace == 0
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    bpp = 3 if ctype == 2 else 4
    raw = zlib.decompress(idat)
    stride = w * bpp
    out, prev = [], bytearray(stride)
    for y in range(h):
        ft = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if ft == 1:
                line[i] = (line[i] + a) & 255
            elif ft == 2:
                line[i] = (line[i] + b) & 255
            elif ft == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif ft == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pr = a if pa <= pb and pa <= pc else b if pb <= pc else c
                line[i] = (line[i] + pr) & 255
        out.append([tuple(line[x * bpp:x * bpp + 3]) for x in range(w)])
        prev = line
    return w, h, out


def centre_of(pixels, rgb, box, tol=6):
    """Centroid of the pixels within tol of rgb inside box (x0, y0, x1,
    y1), and their count."""
    sx = sy = n = 0
    x0, y0, x1, y1 = box
    for y in range(max(0, y0), min(len(pixels), y1)):
        row = pixels[y]
        for x in range(max(0, x0), min(len(row), x1)):
            p = row[x]
            if all(abs(p[k] - rgb[k]) <= tol for k in range(3)):
                sx += x + 0.5
                sy += y + 0.5
                n += 1
    return (sx / n, sy / n, n) if n else (None, None, 0)


def run_model(eom_run, write_page, model, workdir, extra=()):
    """The run's CSV and page: through eom-run --plots when write_page is
    None, else eom-run --out and write_page."""
    name = os.path.basename(model)[:-4]
    csvpath = os.path.join(workdir, name + ".csv")
    if write_page is None:
        cmd = [eom_run, model, "--plots", "-q"]
    else:
        cmd = [eom_run, model, "--out", csvpath, "-q"]
    r = subprocess.run(cmd + list(extra), capture_output=True, text=True,
                       cwd=workdir, timeout=600)
    check(r.returncode == 0, "%s: eom-run: %s" % (name, r.stderr))
    if write_page is not None:
        r = subprocess.run([write_page, model, csvpath], capture_output=True,
                           text=True, cwd=workdir, timeout=600)
        check(r.returncode == 0, "%s: write_page: %s" % (name, r.stderr))
    return os.path.join(workdir, name + "-animation.html"), csvpath


def check_frames(name, page, csvpath, st):
    d = page_data(page)
    table = read_csv(csvpath)
    rows = kept_rows(len(table["t"]), d["nv"])
    check(st["frames"] == len(rows),
          "%s: %d frames, the CSV's rows kept are %d" % (name, st["frames"],
                                                          len(rows)))
    ts = [table["t"][r] for r in rows]
    check(len(d["t"]) == len(ts) and
          all(abs(a - b) <= 1e-6 * max(1, abs(b)) for a, b in zip(d["t"], ts)),
          "%s: the frames' times are not the kept rows' t" % name)
    return d, table, rows


def check_marker(exe, name, page, st, table, rows, where, workdir):
    """The red bob at the first and the last frame, against where(row)."""
    for f in (0, len(rows) - 1):
        png = os.path.join(workdir, "%s-%d.png" % (name, f))
        browser(exe, "file://%s#frame=%d" % (page, f),
                ["--screenshot=" + png], workdir)
        s = st  # the view's place and scale do not change with the frame
        w, h, px = png_pixels(png)
        box = (int(s["left"]), int(s["top"]), int(s["left"] + 800),
               int(s["top"] + 560))
        cx, cy, n = centre_of(px, (0xe4, 0x1a, 0x1c), box)
        x, y = where(table, rows[f])
        ex = s["left"] + s["ox"] + s["scale"] * x
        ey = s["top"] + s["oy"] - s["scale"] * y
        check(n > 20 and abs(cx - ex) <= 2 and abs(cy - ey) <= 2,
              "%s frame %d: the red marker at (%s, %s) (%d px), the CSV "
              "puts it at (%.1f, %.1f)" % (name, f, cx, cy, n, ex, ey))
        if n:
            print("%s frame %d: marker at (%.2f, %.2f), CSV (%.2f, %.2f)"
                  % (name, f, cx, cy, ex, ey))


def double_pendulum_bob(table, r):
    # the model's defaults: l1 = l2 = 1 m
    t1, t2 = table["th1"][r], table["th2"][r]
    return math.sin(t1) + math.sin(t2), -math.cos(t1) - math.cos(t2)


def cart_pole_bob(table, r):
    # l = 0.5 m, theta from the upward vertical
    x, th = table["x"][r], table["theta"][r]
    return x + 0.5 * math.sin(th), 0.5 * math.cos(th)


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    eom_run, write_page = map(os.path.abspath, sys.argv[1:3])
    models = sys.argv[3]
    exe = chromium()
    if not exe:
        print("test_pages: skipped: no chromium on PATH (Debian's package "
              "chromium; tools/install-deps --test installs it)")
        sys.exit(77)
    workdir = tempfile.mkdtemp(prefix="eom-pages-")
    try:
        for model in sorted(os.listdir(models)):
            if not model.endswith(".eom"):
                continue
            name = model[:-4]
            page, csvpath = run_model(
                eom_run, None if name == "double-pendulum" else write_page,
                os.path.join(models, model), workdir, ["--t-end", "3"])
            st, errors = status_of(exe, page, "", workdir)
            check(st is not None and not st["errors"] and not errors,
                  "%s: errors in the page: %s %s" % (
                      name, st and st["errors"], errors))
            if st is None:
                continue
            d, table, rows = check_frames(name, page, csvpath, st)
            print("%s: %d frames, %d bytes, %s" % (
                name, st["frames"], os.path.getsize(page),
                "2-D" if d["planar"] else "3-D"))
            if name == "double-pendulum":
                check_marker(exe, name, page, st, table, rows,
                             double_pendulum_bob, workdir)
                # the slider, moved through the page's #t=
                s, _ = status_of(exe, page, "#t=1.234", workdir)
                want = max(k for k, r in enumerate(rows)
                           if table["t"][r] <= 1.234)
                check(s["frame"] == want and s["slider"] == want and
                      s["label"] == "t = %.3f s" % table["t"][rows[want]],
                      "double-pendulum: #t=1.234 gave %s, expected frame %d"
                      % (s, want))
            if name == "cart-pole":
                check_marker(exe, name, page, st, table, rows,
                             cart_pole_bob, workdir)
            if name == "rolling-disk":
                check(not d["planar"], "rolling-disk is drawn in 2-D")
                png = os.path.join(workdir, "disk.png")
                browser(exe, "file://%s#frame=0" % page,
                        ["--screenshot=" + png], workdir)
                w, h, px = png_pixels(png)
                _, _, n = centre_of(px, (0xe4, 0x1a, 0x1c), (0, 0, w, h), 40)
                check(n > 5, "rolling-disk: the WebGL view shows no red "
                             "marker (%d px)" % n)
        # the budget: a 10,000-row run of the closed chain
        page, csvpath = run_model(eom_run, write_page, os.path.join(
            models, "closed-chain.eom"), workdir,
            ["--t-end", "99.99", "--sample", "0.01"])
        st, errors = status_of(exe, page, "", workdir)
        size = os.path.getsize(page)
        print("closed-chain, 10,000 rows: %d frames, %d bytes" % (
            st["frames"] if st else -1, size))
        check(st is not None and not st["errors"] and not errors,
              "closed-chain 10,000 rows: errors %s" % errors)
        if st:
            d, table, rows = check_frames("closed-chain 10,000 rows", page,
                                          csvpath, st)
            check(len(table["t"]) == 10000, "the large run has %d rows"
                  % len(table["t"]))
            check(1000 < st["frames"] <= 2000,
                  "the large run kept %d frames" % st["frames"])
        check(size < 5 * 1024 * 1024, "the large run's page is %d bytes"
              % size)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    print("%d checks, %d failed" % (CHECKS[0], len(FAILS)))
    sys.exit(1 if FAILS else 0)


main()
