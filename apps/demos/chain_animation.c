/* chain_animation.c - the HTML animation of a chain (see
 * chain_animation.h). The page is fixed text around two generated parts:
 * the chain's description (lengths, modes, pins) and the frames. The
 * fixed text is split into short literals: ISO C promises only 4095
 * characters per string literal. */
#include "chain_animation.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *const page_head[] = {
    "<!DOCTYPE html>\n",
    "<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n",
    "<meta name=\"viewport\" content=\"width=device-width\">\n",
    "<style>\n",
    "body { font-family: sans-serif; margin: 1em; color: #222; }\n",
    "h1 { font-size: 1.1em; }\n",
    "#bar { display: flex; flex-wrap: wrap; gap: 0.8em; align-items: "
    "center; margin-bottom: 0.5em; }\n",
    "#time { font-family: monospace; min-width: 14em; }\n",
    "canvas { border: 1px solid #bbb; max-width: 100%; }\n",
    "p { font-size: 0.9em; color: #555; }\n",
    "</style>\n",
    NULL};

static const char *const page_controls[] = {
    "<div id=\"bar\">\n",
    "<button id=\"play\" type=\"button\">Pause</button>\n",
    "<input id=\"slider\" type=\"range\" min=\"0\" value=\"0\" "
    "style=\"flex: 1; min-width: 12em\" aria-label=\"time\">\n",
    "<span id=\"time\"></span>\n",
    "<label>speed <select id=\"speed\">",
    "<option>0.1</option><option>0.25</option><option>0.5</option>",
    "<option selected>1</option><option>2</option><option>4</option>",
    "</select> &times;</label>\n",
    "<label>deflection &times; <input id=\"exag\" type=\"number\" min=\"0\" "
    "step=\"any\" style=\"width: 6em\"></label>\n",
    "</div>\n",
    "<canvas id=\"view\" width=\"960\" height=\"640\"></canvas>\n",
    NULL};

/* The player. Reads the globals chain and frames written before it. */
static const char *const page_script[] = {
    "const canvas = document.getElementById('view');\n",
    "const ctx = canvas.getContext('2d');\n",
    "const slider = document.getElementById('slider');\n",
    "const label = document.getElementById('time');\n",
    "const button = document.getElementById('play');\n",
    "const speedBox = document.getElementById('speed');\n",
    "const exagBox = document.getElementById('exag');\n",
    "const N = chain.L.length;\n",
    "const tEnd = frames[frames.length - 1][0];\n",
    "let exag = chain.exaggeration, box = null;\n",
    "let playing = true, frame = 0, simTime = 0, lastWall = null;\n",
    "slider.max = frames.length - 1;\n",
    "exagBox.value = exag;\n",
    "\n",
    "// The links of frame f: one array of [x, y] points per link,\n",
    "// r_j(x) = R_j + x e_j + s v_j(x) n_j (docs/elements.md).\n",
    "function shape(f, s) {\n",
    "  const links = [];\n",
    "  let rx = 0, ry = 0, qk = 1 + N;\n",
    "  for (let j = 0; j < N; j++) {\n",
    "    const th = f[1 + j], L = chain.L[j], K = chain.modes[j];\n",
    "    const ex = Math.cos(th), ey = Math.sin(th);\n",
    "    const np = K > 0 ? 12 * K + 1 : 2, pts = [];\n",
    "    for (let p = 0; p < np; p++) {\n",
    "      const x = L * p / (np - 1);\n",
    "      let v = 0;\n",
    "      for (let k = 0; k < K; k++)\n",
    "        v += f[qk + k] * Math.sin((k + 1) * Math.PI * x / L);\n",
    "      pts.push([rx + x * ex - s * v * ey, ry + x * ey + s * v * ex]);\n",
    "    }\n",
    "    links.push(pts);\n",
    "    rx += L * ex; ry += L * ey; qk += K;\n",
    "  }\n",
    "  return links;\n",
    "}\n",
    "\n",
    "// The box that holds every frame, so the view does not jump.\n",
    "function bounds() {\n",
    "  let x0 = 0, x1 = 0, y0 = 0, y1 = 0;\n",
    "  if (chain.closed) { x0 = Math.min(x0, chain.D); "
    "x1 = Math.max(x1, chain.D); }\n",
    "  const step = Math.max(1, Math.floor(frames.length / 400));\n",
    "  for (let i = 0; i < frames.length; i += step)\n",
    "    for (const pts of shape(frames[i], exag))\n",
    "      for (const [x, y] of pts) {\n",
    "        x0 = Math.min(x0, x); x1 = Math.max(x1, x);\n",
    "        y0 = Math.min(y0, y); y1 = Math.max(y1, y);\n",
    "      }\n",
    "  const pad = 0.05 * Math.max(x1 - x0, y1 - y0, 1e-9);\n",
    "  return [x0 - pad, x1 + pad, y0 - pad, y1 + pad];\n",
    "}\n",
    "\n",
    "function pin(x, y, sc) {\n",
    "  const h = 10;\n",
    "  ctx.fillStyle = '#444';\n",
    "  ctx.beginPath(); ctx.moveTo(x, y); ctx.lineTo(x - h, y + 1.6 * h);\n",
    "  ctx.lineTo(x + h, y + 1.6 * h); ctx.closePath(); ctx.fill();\n",
    "}\n",
    "\n",
    "function draw() {\n",
    "  const [x0, x1, y0, y1] = box;\n",
    "  const W = canvas.width, H = canvas.height, m = 24;\n",
    "  const sc = Math.min((W - 2 * m) / (x1 - x0), (H - 2 * m) / (y1 - y0));\n",
    "  const ox = (W - sc * (x1 - x0)) / 2, oy = (H - sc * (y1 - y0)) / 2;\n",
    "  const X = x => ox + sc * (x - x0), Y = y => H - oy - sc * (y - y0);\n",
    "  ctx.clearRect(0, 0, W, H);\n",
    "  ctx.strokeStyle = '#ddd'; ctx.lineWidth = 1;\n",
    "  ctx.beginPath(); ctx.moveTo(0, Y(0)); ctx.lineTo(W, Y(0)); "
    "ctx.stroke();\n",
    "  pin(X(0), Y(0), sc);\n",
    "  if (chain.closed) pin(X(chain.D), Y(0), sc);\n",
    "  const colors = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', "
    "'#ff7f0e', '#8c564b'];\n",
    "  const links = shape(frames[frame], exag);\n",
    "  ctx.lineWidth = 3; ctx.lineJoin = 'round';\n",
    "  links.forEach((pts, j) => {\n",
    "    ctx.strokeStyle = colors[j % colors.length];\n",
    "    ctx.beginPath();\n",
    "    pts.forEach(([x, y], p) => p ? ctx.lineTo(X(x), Y(y)) : "
    "ctx.moveTo(X(x), Y(y)));\n",
    "    ctx.stroke();\n",
    "  });\n",
    "  ctx.fillStyle = '#000';\n",
    "  for (const pts of links) {\n",
    "    const [x, y] = pts[0];\n",
    "    ctx.beginPath(); ctx.arc(X(x), Y(y), 4, 0, 2 * Math.PI); "
    "ctx.fill();\n",
    "  }\n",
    "  const t = frames[frame][0];\n",
    "  label.textContent = 't = ' + t.toFixed(3) + ' s / ' + tEnd + ' s';\n",
    "  slider.value = frame;\n",
    "}\n",
    "\n",
    "// The last frame at or before time t (frames are in time order).\n",
    "function frameAt(t) {\n",
    "  let lo = 0, hi = frames.length - 1;\n",
    "  while (lo < hi) {\n",
    "    const mid = (lo + hi + 1) >> 1;\n",
    "    if (frames[mid][0] <= t) lo = mid; else hi = mid - 1;\n",
    "  }\n",
    "  return lo;\n",
    "}\n",
    "\n",
    "function tick(wall) {\n",
    "  if (playing) {\n",
    "    if (lastWall !== null)\n",
    "      simTime += (wall - lastWall) / 1000 * Number(speedBox.value);\n",
    "    if (simTime > tEnd) simTime = 0;\n",
    "    frame = frameAt(simTime);\n",
    "    draw();\n",
    "  }\n",
    "  lastWall = wall;\n",
    "  requestAnimationFrame(tick);\n",
    "}\n",
    "\n",
    "function setPlaying(on) {\n",
    "  playing = on;\n",
    "  button.textContent = on ? 'Pause' : 'Play';\n",
    "}\n",
    "button.onclick = () => setPlaying(!playing);\n",
    "document.addEventListener('keydown', e => {\n",
    "  if (e.key === ' ' && e.target.tagName !== 'INPUT') {\n",
    "    e.preventDefault(); setPlaying(!playing);\n",
    "  }\n",
    "});\n",
    "slider.oninput = () => {\n",
    "  setPlaying(false);\n",
    "  frame = Number(slider.value); simTime = frames[frame][0]; draw();\n",
    "};\n",
    "exagBox.onchange = () => {\n",
    "  const v = Number(exagBox.value);\n",
    "  if (v >= 0 && isFinite(v)) { exag = v; box = bounds(); draw(); }\n",
    "};\n",
    "box = bounds();\n",
    "draw();\n",
    "requestAnimationFrame(tick);\n",
    NULL};

static void put_all(FILE *f, const char *const *lines)
{
    for (; *lines; lines++)
        fputs(*lines, f);
}

/* text with & < > " escaped for HTML. */
static void put_escaped(FILE *f, const char *text)
{
    for (; *text; text++)
        switch (*text) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*text, f);
        }
}

/* A number for JavaScript: finite values only (JSON has no nan). */
static void put_number(FILE *f, double v)
{
    if (!isfinite(v))
        fputs("0", f);
    else
        fprintf(f, "%.9g", v);
}

static void put_chain(FILE *f, const chain_shape *c, double exaggeration)
{
    int j;
    fputs("const chain = {\n  L: [", f);
    for (j = 0; j < c->links; j++) {
        if (j)
            fputs(", ", f);
        put_number(f, c->L[j]);
    }
    fputs("],\n  modes: [", f);
    for (j = 0; j < c->links; j++)
        fprintf(f, "%s%d", j ? ", " : "", c->modes[j]);
    fprintf(f, "],\n  closed: %s,\n  D: ", c->closed ? "true" : "false");
    put_number(f, c->D);
    fputs(",\n  exaggeration: ", f);
    put_number(f, exaggeration);
    fputs("\n};\n", f);
}

/* One line per frame: t, the angles, then the modal amplitudes link by
 * link, the order shape() in the page reads them. */
static void put_frames(FILE *f, const chain_shape *c, const eom_csv_table *t)
{
    const int tcol = eom_csv_table_col(t, "t");
    const int stride = t->nrows > CHAIN_ANIMATION_MAX_FRAMES
                           ? (t->nrows + CHAIN_ANIMATION_MAX_FRAMES - 2) /
                                 (CHAIN_ANIMATION_MAX_FRAMES - 1)
                           : 1;
    int i, j, k;
    fputs("const frames = [\n", f);
    for (i = 0; i < t->nrows; i += stride) {
        /* the last frame is the end of the run, whatever the stride */
        const int r = i + stride >= t->nrows ? t->nrows - 1 : i;
        fputc('[', f);
        put_number(f, eom_csv_table_at(t, r, tcol));
        for (j = 0; j < c->links; j++) {
            fputc(',', f);
            put_number(f, eom_csv_table_at(t, r, c->theta_col[j]));
        }
        for (j = 0; j < c->links; j++)
            for (k = 0; k < c->modes[j]; k++) {
                fputc(',', f);
                put_number(f, eom_csv_table_at(t, r,
                                               c->q_col[c->q_first[j] + k]));
            }
        fputs("],\n", f);
        if (r == t->nrows - 1)
            break;
    }
    fputs("];\n", f);
}

int chain_animation_write(const char *path, const chain_shape *c,
                          const eom_csv_table *t, const char *title,
                          double exaggeration, int gravity, char *err,
                          size_t errlen)
{
    FILE *f;
    if (t->nrows < 1 || eom_csv_table_col(t, "t") < 0) {
        snprintf(err, errlen, "the CSV has no rows or no column 't'");
        return -1;
    }
    f = fopen(path, "w");
    if (!f) {
        snprintf(err, errlen, "cannot open '%s' for writing: %s", path,
                 strerror(errno));
        return -1;
    }
    errno = 0;
    put_all(f, page_head);
    fputs("<title>", f);
    put_escaped(f, title);
    fputs("</title>\n</head>\n<body>\n<h1>", f);
    put_escaped(f, title);
    fputs("</h1>\n", f);
    put_all(f, page_controls);
    fputs("<p>The deflection of each link is drawn magnified by the factor "
          "above (1: true scale); the chords join the joints (dots)", f);
    fputs(gravity ? ". Gravity acts downwards (along -y).</p>\n"
                  : ". No gravity.</p>\n", f);
    fputs("<script>\n\"use strict\";\n", f);
    put_chain(f, c, exaggeration);
    put_frames(f, c, t);
    put_all(f, page_script);
    fputs("</script>\n</body>\n</html>\n", f);
    if (ferror(f)) {
        snprintf(err, errlen, "cannot write to '%s': %s", path,
                 errno ? strerror(errno) : "write error");
        fclose(f);
        return -1;
    }
    if (fclose(f) != 0) {
        snprintf(err, errlen, "cannot write to '%s': %s", path,
                 strerror(errno));
        return -1;
    }
    return 0;
}
