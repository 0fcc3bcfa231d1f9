#!/usr/bin/env python3
"""test_pages.py - the animation pages of eom-run and eom-ensemble in a
real browser (headless Chromium from Debian, started once and driven over
the DevTools protocol on a pipe: cdp.py; docs/run.md, "The animation
page", docs/ensembles.md).

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

The ensemble's page (eom-ensemble --trajectories DIR --plots): ten runs
of the double pendulum drawn, one legend entry each, each run's frames
its CSV's rows kept by the shared budget, and at the first and the last
frame the lower bob of two runs, each in its run's colour, within 2 px
of where that run's CSV puts it; a spatial ensemble's WebGL page shows
each run's colour.

usage: test_pages.py EOM_RUN WRITE_PAGE EOM_ENSEMBLE MODELS_DIR
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

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cdp import Browser, BrowserError  # noqa: E402

FAILS = []
CHECKS = [0]
# seconds for any one answer of the browser (its start, a page's load, a
# screenshot); a loaded 2-core machine needs about 15 for the first page
TIMEOUT = 120

# the colours of an ensemble's runs, in turn (docs/run.md)
RUN_COLOURS = [0x1f77b4, 0xff7f0e, 0x2ca02c, 0xd62728, 0x9467bd, 0x8c564b,
               0xe377c2, 0x7f7f7f, 0xbcbd22, 0x17becf]


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


def status_of(b, page, frag):
    """The page's #status object after load, and its console errors."""
    tab = b.open("file://" + page + frag)
    try:
        st = tab.status()
        errors = tab.errors
    finally:
        tab.close()
    if st is None:
        return None, errors + ["no status in the page"]
    return st, errors


def screenshots(b, url, shots):
    """Screenshots of url: for each (png, clip) of shots, the part clip
    (x, y, width, height, scale; None: the whole window) into png. Small
    clips keep the decoding here (pure Python) short."""
    tab = b.open(url)
    try:
        tab.status()  # its first frame is drawn
        for png, clip in shots:
            tab.screenshot(png, clip)
    finally:
        tab.close()


def marker_at(png, rgb, ex, ey, half=10):
    """The centroid (in the page's pixels) and count of the pixels of
    colour rgb within half px of (ex, ey), from png, a clip taken at
    (int(ex) - 20, int(ey) - 20)."""
    x0, y0 = int(ex) - 20, int(ey) - 20
    w, h, px = png_pixels(png)
    cx, cy, n = centre_of(px, rgb, (int(ex) - half - x0, int(ey) - half - y0,
                                    int(ex) + half + 1 - x0,
                                    int(ey) + half + 1 - y0))
    return (cx + x0 if n else None), (cy + y0 if n else None), n


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


def check_marker(b, name, page, st, table, rows, where, workdir):
    """The red bob at the first and the last frame, against where(row):
    its pixels within 10 px of where the CSV puts it."""
    for f in (0, len(rows) - 1):
        png = os.path.join(workdir, "%s-%d.png" % (name, f))
        s = st  # the view's place and scale do not change with the frame
        x, y = where(table, rows[f])
        ex = s["left"] + s["ox"] + s["scale"] * x
        ey = s["top"] + s["oy"] - s["scale"] * y
        screenshots(b, "file://%s#frame=%d" % (page, f),
                    [(png, (int(ex) - 20, int(ey) - 20, 41, 41, 1))])
        cx, cy, n = marker_at(png, (0xe4, 0x1a, 0x1c), ex, ey)
        check(n > 60 and abs(cx - ex) <= 2 and abs(cy - ey) <= 2,
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


def kept_rows_shared(nrows_of_runs, nv):
    """docs/run.md: an ensemble's page keeps at most 2000 frames and
    300000 drawn values over all runs; one stride for every run, the
    smallest that fits the longest, and each run's last row."""
    runs = len(nrows_of_runs)
    budget = max(2, min(2000, 300000 // (max(nv, 1) * runs)))
    longest = max(nrows_of_runs)
    k = 1
    while len(range(0, longest, k)) + ((longest - 1) % k != 0) > budget:
        k += 1
    out = []
    for n in nrows_of_runs:
        rows = list(range(0, n, k))
        if rows[-1] != n - 1:
            rows.append(n - 1)
        out.append(rows)
    return out


def rgb_of(c):
    return ((c >> 16) & 255, (c >> 8) & 255, c & 255)


def check_ensemble(b, eom_ensemble, models, workdir):
    """Ten runs of the double pendulum in one page (eom-ensemble
    --trajectories DIR --plots)."""
    name, nruns = "ensemble", 10
    r = subprocess.run(
        [eom_ensemble, os.path.join(models, "double-pendulum.eom"),
         "--sweep", "th1=0.5:2.5:%d" % nruns, "--set", "th2=0",
         "--set", "th2_dot=2", "--t-end", "2", "--sample", "0.05",
         "--trajectories", "traj", "--plots", "--out", "dp.csv", "-q"],
        capture_output=True, text=True, cwd=workdir, timeout=600)
    check(r.returncode == 0, "eom-ensemble --plots: %s" % r.stderr)
    page = os.path.join(workdir, "dp-animation.html")
    if r.returncode != 0 or not os.path.exists(page):
        return
    st, errors = status_of(b, page, "")
    check(st is not None and not st["errors"] and not errors,
          "%s: errors in the page: %s %s" % (name, st and st["errors"],
                                             errors))
    if st is None:
        return
    d = page_data(page)
    tables = [read_csv(os.path.join(workdir, "traj", "run-%d.csv" % k))
              for k in range(nruns)]
    # every run drawn, each with its legend entry and colour
    check(st["runs"] == nruns and len(d["runs"]) == nruns,
          "%s: %s runs drawn, %d in the page, the ensemble has %d"
          % (name, st["runs"], len(d["runs"]), nruns))
    tab = b.open("file://" + page)
    try:
        entries = tab.eval("Array.from(document.querySelectorAll("
                           "'#legend span.run')).map(e => e.textContent)")
    finally:
        tab.close()
    check(entries == ["run %d: th1=%.6g" % (k, 0.5 + 2.0 * k / (nruns - 1))
                      for k in range(nruns)],
          "%s: the legend is %s" % (name, entries))
    check([run["rgb"] for run in d["runs"]] == RUN_COLOURS[:nruns],
          "%s: the runs' colours are not the documented ones" % name)
    # each run's frames: its CSV's rows kept by the shared budget
    kept = kept_rows_shared([len(t["t"]) for t in tables], d["nv"])
    for k in range(nruns):
        ts = [tables[k]["t"][i] for i in kept[k]]
        check(len(d["runs"][k]["t"]) == len(ts) and
              all(abs(x - y) <= 1e-6 * max(1, abs(y))
                  for x, y in zip(d["runs"][k]["t"], ts)),
              "%s: run %d's frames are not its CSV's kept rows" % (name, k))
    check(st["frames"] == max(len(rows) for rows in kept),
          "%s: the slider has %d frames" % (name, st["frames"]))
    print("%s: %d runs, %d frames, %d bytes" % (
        name, nruns, st["frames"], os.path.getsize(page)))
    for f in (0, st["frames"] - 1):
        def at(xy):
            return (st["left"] + st["ox"] + st["scale"] * xy[0],
                    st["top"] + st["oy"] - st["scale"] * xy[1])
        # every drawn point of every run at this frame (the runs all
        # have the slider's frames here), in the page's pixels
        rows = [kept[k][min(f, len(kept[k]) - 1)] for k in range(nruns)]
        bob1 = [at((math.sin(t["th1"][i]), -math.cos(t["th1"][i])))
                for t, i in zip(tables, rows)]
        bob2 = [at(double_pendulum_bob(t, i)) for t, i in zip(tables, rows)]

        def clear(k):
            # no point of a run drawn later within 13 px (it would cover
            # part of run k's bob), the run's own upper bob 18 px away
            later = [p for j in range(k + 1, nruns) for p in (bob1[j],
                                                              bob2[j])]
            near = [math.hypot(p[0] - bob2[k][0], p[1] - bob2[k][1])
                    for p in later]
            return min(near + [99]) > 13 and math.hypot(
                bob1[k][0] - bob2[k][0], bob1[k][1] - bob2[k][1]) > 18
        chosen = [k for k in range(nruns) if clear(k)][:2]
        check(len(chosen) == 2, "%s frame %d: fewer than two runs' bobs "
              "stand apart (%s)" % (name, f, chosen))
        pngs = [os.path.join(workdir, "%s-%d-%d.png" % (name, f, k))
                for k in chosen]
        screenshots(b, "file://%s#frame=%d" % (page, f),
                    [(png, (int(bob2[k][0]) - 20, int(bob2[k][1]) - 20, 41,
                            41, 1)) for png, k in zip(pngs, chosen)])
        for png, k in zip(pngs, chosen):
            ex, ey = bob2[k]
            cx, cy, n = marker_at(png, rgb_of(RUN_COLOURS[k]), ex, ey)
            check(n > 60 and abs(cx - ex) <= 2 and abs(cy - ey) <= 2,
                  "%s frame %d: run %d's bob in its colour at (%s, %s) "
                  "(%d px), its CSV puts it at (%.1f, %.1f)"
                  % (name, f, k, cx, cy, n, ex, ey))
            if n:
                print("%s frame %d run %d: bob at (%.2f, %.2f), CSV "
                      "(%.2f, %.2f), %d px" % (name, f, k, cx, cy, ex, ey,
                                               n))
    # a spatial model: three runs in the WebGL view, each in its colour
    r = subprocess.run(
        [eom_ensemble, os.path.join(models, "spherical-double-pendulum.eom"),
         "--sweep", "b1=0.3:0.9:3", "--t-end", "1", "--sample", "0.05",
         "--trajectories", "traj3", "--plots", "--out", "sdp.csv", "-q"],
        capture_output=True, text=True, cwd=workdir, timeout=600)
    check(r.returncode == 0, "eom-ensemble --plots (spatial): %s %s"
          % (r.returncode, r.stderr))
    page = os.path.join(workdir, "sdp-animation.html")
    if r.returncode != 0 or not os.path.exists(page):
        return
    st, errors = status_of(b, page, "#frame=0")
    check(st is not None and not st["errors"] and not errors and
          st["runs"] == 3,
          "spatial ensemble: %s %s" % (st, errors))
    d = page_data(page)
    check(not d["planar"] and len(d["runs"]) == 3,
          "spatial ensemble: planar %s, %d runs" % (d["planar"],
                                                   len(d["runs"])))
    png = os.path.join(workdir, "sdp.png")
    # the view at half scale: enough to see the colours, a quarter of
    # the pixels to decode
    screenshots(b, "file://%s#frame=0" % page,
                [(png, (int(st["left"]), int(st["top"]), 800, 560, 0.5))])
    w, h, px = png_pixels(png)
    for k in range(3):
        _, _, n = centre_of(px, rgb_of(RUN_COLOURS[k]), (0, 0, w, h), 40)
        check(n > 5, "spatial ensemble: the WebGL view shows no run %d "
                     "colour (%d px)" % (k, n))


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    eom_run, write_page, eom_ensemble = map(os.path.abspath, sys.argv[1:4])
    models = sys.argv[4]
    exe = chromium()
    if not exe:
        print("test_pages: skipped: no chromium on PATH (Debian's package "
              "chromium; tools/install-deps --test installs it)")
        sys.exit(77)
    workdir = tempfile.mkdtemp(prefix="eom-pages-")
    try:
        with Browser(exe, workdir, TIMEOUT) as b:
            pages(b, eom_run, write_page, eom_ensemble, models, workdir)
    except BrowserError as e:
        check(False, "the browser: %s" % e)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    print("%d checks, %d failed" % (CHECKS[0], len(FAILS)))
    sys.exit(1 if FAILS else 0)


def pages(b, eom_run, write_page, eom_ensemble, models, workdir):
    """Every check, in the one browser b."""
    for model in sorted(os.listdir(models)):
        if not model.endswith(".eom"):
            continue
        name = model[:-4]
        page, csvpath = run_model(
            eom_run, None if name == "double-pendulum" else write_page,
            os.path.join(models, model), workdir, ["--t-end", "3"])
        st, errors = status_of(b, page, "")
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
            check_marker(b, name, page, st, table, rows,
                         double_pendulum_bob, workdir)
            # the slider, moved through the page's #t=
            s, _ = status_of(b, page, "#t=1.234")
            want = max(k for k, r in enumerate(rows)
                       if table["t"][r] <= 1.234)
            check(s["frame"] == want and s["slider"] == want and
                  s["label"] == "t = %.3f s" % table["t"][rows[want]],
                  "double-pendulum: #t=1.234 gave %s, expected frame %d"
                  % (s, want))
        if name == "cart-pole":
            check_marker(b, name, page, st, table, rows,
                         cart_pole_bob, workdir)
        if name == "rolling-disk":
            check(not d["planar"], "rolling-disk is drawn in 2-D")
            with open(page, encoding="utf-8") as f:
                has_three = "/* three.js " in f.read()
            check(has_three, "rolling-disk: the page has no three.js, so "
                  "no 3-D view: this build was configured without "
                  "vendor/three (tools/install-deps --test fetches it; "
                  "then reconfigure)")
            png = os.path.join(workdir, "disk.png")
            screenshots(b, "file://%s#frame=0" % page,
                        [(png, (int(st["left"]), int(st["top"]), 800, 560,
                                0.5))])
            w, h, px = png_pixels(png)
            _, _, n = centre_of(px, (0xe4, 0x1a, 0x1c), (0, 0, w, h), 40)
            check(n > 5, "rolling-disk: the WebGL view shows no red "
                         "marker (%d px)" % n)
    check_ensemble(b, eom_ensemble, models, workdir)
    # the budget: a 10,000-row run of the closed chain
    page, csvpath = run_model(eom_run, write_page, os.path.join(
        models, "closed-chain.eom"), workdir,
        ["--t-end", "99.99", "--sample", "0.01"])
    st, errors = status_of(b, page, "")
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


main()
