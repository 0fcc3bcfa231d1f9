/* compile.c - compiled tapes: build the generated source (codegen.c) with
 * the system's C compiler into a shared object, keep it in a per-user
 * cache, load it, and check it against the interpreter before any sweep
 * uses it.
 *
 * The cache. An entry is named by a 128-bit hash of everything that
 * decides the machine code: the generated source (which holds the tape and
 * the kernels' text), the compiler command and its flags, and the format.
 * Beside the object, NAME.sum records its key, size and a hash of its
 * bytes, written after the object is complete; an entry is loaded only if
 * both agree with the object on disk, so a truncated, corrupt or foreign
 * file is rebuilt, never loaded. After loading, the object must report the
 * same key and format, and its sweeps must give the interpreter's results
 * at one state (tp_compile_opts.x). Objects are built under temporary
 * names and renamed into place, so concurrent builds of one tape (threads,
 * processes) each see a whole file.
 *
 * Nothing here fails a caller's computation: every failure is a status
 * and a message, and the tape keeps running on the interpreter.
 */
#define _POSIX_C_SOURCE 200809L

#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <spawn.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "codegen.h"

extern char **environ;

#define PATH_LEN 4096
#define MAX_ARGS 64

static void say(tp_compile_info *info, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static void say(tp_compile_info *info, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(info->msg, sizeof info->msg, fmt, ap);
    va_end(ap);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- hashing ----------------------------------------------------------- */

/* Two 64-bit FNV-1a lanes with different bases, each finished by a
 * splitmix64 mix: a 128-bit name for a cache entry (not a defence against
 * someone who can write the user's cache; a check against accidents). */
typedef struct hash128 {
    uint64_t a, b;
} hash128;

static void hash_init(hash128 *h)
{
    h->a = 0xcbf29ce484222325ull;
    h->b = 0x84222325cbf29ce4ull;
}

static void hash_bytes(hash128 *h, const void *p, size_t n)
{
    const unsigned char *c = p;
    size_t i;
    for (i = 0; i < n; i++) {
        h->a = (h->a ^ c[i]) * 0x100000001b3ull;
        h->b = (h->b ^ (uint64_t)(c[i] + 0x5bu)) * 0x100000001b3ull;
    }
}

static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static void hash_hex(const hash128 *h, char out[33])
{
    snprintf(out, 33, "%016llx%016llx", (unsigned long long)mix64(h->a),
             (unsigned long long)mix64(h->b ^ h->a));
}

/* ---- files ------------------------------------------------------------- */

/* Read a whole file (at most max bytes); NULL if it cannot be read. */
static unsigned char *read_file(const char *path, size_t max, size_t *n)
{
    FILE *f = fopen(path, "rb");
    unsigned char *p = NULL;
    long len;
    if (!f)
        return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (len = ftell(f)) >= 0 &&
        (size_t)len <= max && fseek(f, 0, SEEK_SET) == 0 &&
        (p = malloc((size_t)len + 1)) != NULL) {
        if (fread(p, 1, (size_t)len, f) != (size_t)len) {
            free(p);
            p = NULL;
        } else {
            p[len] = 0;
            *n = (size_t)len;
        }
    }
    fclose(f);
    return p;
}

static int write_file(const char *path, const char *p, size_t n)
{
    FILE *f = fopen(path, "wb");
    int ok;
    if (!f)
        return -1;
    ok = fwrite(p, 1, n, f) == n;
    ok = fclose(f) == 0 && ok;
    return ok ? 0 : -1;
}

/* mkdir -p with mode 0700 for the directories it creates. */
static int make_dirs(const char *dir)
{
    char p[PATH_LEN];
    size_t k;
    if (strlen(dir) >= sizeof p)
        return -1;
    strcpy(p, dir);
    for (k = 1; p[k]; k++) {
        if (p[k] != '/')
            continue;
        p[k] = 0;
        if (mkdir(p, 0700) != 0 && errno != EEXIST)
            return -1;
        p[k] = '/';
    }
    if (mkdir(p, 0700) != 0 && errno != EEXIST)
        return -1;
    return 0;
}

static int cache_dir(const tp_compile_opts *o, char *out, size_t len)
{
    const char *e;
    int n;
    if (o && o->cache_dir && *o->cache_dir)
        n = snprintf(out, len, "%s", o->cache_dir);
    else if ((e = getenv("AUTOEOM_CACHE_DIR")) && *e)
        n = snprintf(out, len, "%s", e);
    else if ((e = getenv("XDG_CACHE_HOME")) && *e == '/')
        n = snprintf(out, len, "%s/autoeom", e);
    else if ((e = getenv("HOME")) && *e)
        n = snprintf(out, len, "%s/.cache/autoeom", e);
    else
        return -1;
    return n > 0 && (size_t)n < len ? 0 : -1;
}

/* dir/base.ext into out; -1 if it does not fit. */
static int path_of(char *out, size_t len, const char *dir, const char *base,
                   const char *ext)
{
    const int n = snprintf(out, len, "%s/%s%s", dir, base, ext);
    return n >= 0 && (size_t)n < len ? 0 : -1;
}

/* ---- cache entries ----------------------------------------------------- */

#define SUM_MAGIC "autoeom compiled tape"

static int write_sum(const char *so, const char *sum, const char *key)
{
    size_t n = 0;
    unsigned char *p = read_file(so, (size_t)1 << 31, &n);
    char text[256], hex[33];
    hash128 h;
    int len;
    if (!p)
        return -1;
    hash_init(&h);
    hash_bytes(&h, p, n);
    free(p);
    hash_hex(&h, hex);
    len = snprintf(text, sizeof text, "%s %d\nkey %s\nbytes %zu\nhash %s\n",
                   SUM_MAGIC, TP_CODEGEN_FORMAT, key, n, hex);
    return write_file(sum, text, (size_t)len);
}

/* 1 if the entry (so, sum) is whole and belongs to key; 0 if there is no
 * entry; -1 (and why) if there is one that must not be loaded. */
static int entry_ok(const char *so, const char *sum, const char *key,
                    char *why, size_t len)
{
    size_t n = 0, ns = 0;
    unsigned char *p, *s;
    char expect[256], hex[33];
    hash128 h;
    int ok;
    struct stat st;
    if (stat(so, &st) != 0 && stat(sum, &st) != 0)
        return 0;
    s = read_file(sum, 4096, &ns);
    p = read_file(so, (size_t)1 << 31, &n);
    if (!s || !p) {
        snprintf(why, len, "%s", s ? "its object cannot be read"
                                   : "its checksum file is missing");
        free(s);
        free(p);
        return -1;
    }
    hash_init(&h);
    hash_bytes(&h, p, n);
    free(p);
    hash_hex(&h, hex);
    snprintf(expect, sizeof expect, "%s %d\nkey %s\nbytes %zu\nhash %s\n",
             SUM_MAGIC, TP_CODEGEN_FORMAT, key, n, hex);
    ok = strcmp((const char *)s, expect) == 0;
    if (!ok)
        snprintf(why, len, "%s",
                 strncmp((const char *)s, SUM_MAGIC, strlen(SUM_MAGIC)) != 0
                     ? "its checksum file is not one of ours"
                 : strstr((const char *)s, key) == NULL
                     ? "it belongs to another tape or compiler"
                     : "its object does not match its checksum (corrupt)");
    free(s);
    return ok ? 1 : -1;
}

/* ---- loading and checking ---------------------------------------------- */

static void unload(tp_compiled *c)
{
    if (c->dl)
        dlclose(c->dl);
    c->dl = NULL;
}

static int load(tp_compiled *c, const char *so, const char *key,
                tp_compile_info *info)
{
    const int *format;
    const uint32_t *nops;
    const size_t *kxs;
    const int *P;
    const unsigned *sweeps;
    const char *k;
    c->dl = dlopen(so, RTLD_NOW | RTLD_LOCAL);
    if (!c->dl) {
        const char *e = dlerror();
        say(info, "cannot load %s: %s", so, e ? e : "unknown error");
        return -1;
    }
    format = dlsym(c->dl, "tpc_format");
    nops = dlsym(c->dl, "tpc_nops");
    kxs = dlsym(c->dl, "tpc_kx_size");
    k = dlsym(c->dl, "tpc_key");
    P = dlsym(c->dl, "tpc_P");
    sweeps = dlsym(c->dl, "tpc_sweeps");
    c->fwd0 = c->rev1 = NULL;
    if (c->sweeps & TP_SWEEP_VALUES)
        *(void **)&c->fwd0 = dlsym(c->dl, "tpc_fwd0");
    if (c->sweeps & TP_SWEEP_GRADIENTS)
        *(void **)&c->rev1 = dlsym(c->dl, "tpc_rev1");
    c->jacobian = NULL;
    if (c->sweeps & TP_SWEEP_JACOBIAN) {
        const int *shape = dlsym(c->dl, "tpc_jacobian_shape");
        *(void **)&c->jacobian = dlsym(c->dl, "tpc_jacobian");
        if (!shape || shape[0] != (int)c->t->n_indep || shape[1] != c->P)
            c->jacobian = NULL;
    }
    c->taylor2 = NULL;
    if (c->sweeps & TP_SWEEP_TAYLOR2)
        *(void **)&c->taylor2 = dlsym(c->dl, "tpc_taylor2");
    c->lagrange = NULL;
    if (c->lout >= 0) {
        const int *shape = dlsym(c->dl, "tpc_lagrange_shape");
        *(void **)&c->lagrange = dlsym(c->dl, "tpc_lagrange");
        if (!shape || shape[0] != c->lout || shape[1] != c->lfirst ||
            shape[2] != c->lcount || shape[3] != c->P)
            c->lagrange = NULL;
    }
    if (!format || !nops || !kxs || !k || !sweeps || *sweeps != c->sweeps ||
        (!c->fwd0 && (c->sweeps & TP_SWEEP_VALUES)) ||
        (!c->rev1 && (c->sweeps & TP_SWEEP_GRADIENTS)) ||
        (!c->jacobian && (c->sweeps & TP_SWEEP_JACOBIAN)) ||
        (!c->taylor2 && (c->sweeps & TP_SWEEP_TAYLOR2)) ||
        (c->lout >= 0 && !c->lagrange) || !P ||
        *P != c->P ||
        *format != TP_CODEGEN_FORMAT ||
        *nops != c->t->n_ops || *kxs != sizeof(tp_kx) || strcmp(k, key) != 0) {
        say(info, "%s is not the compiled form of this tape", so);
        unload(c);
        return -1;
    }
    return 0;
}

static bool agree(double a, double b)
{
    if (a == b || (isnan(a) && isnan(b)))
        return true;
    return fabs(a - b) <= 1e-13 * fmax(fabs(a), fabs(b));
}

/* Compare n results of the two paths; on a difference name it. */
static bool same(const double *a, const double *b, size_t n, const char *what,
                 tp_compile_info *info)
{
    size_t k;
    for (k = 0; k < n; k++)
        if (!agree(a[k], b[k])) {
            say(info,
                "the compiled tape differs from the interpreter (%s, entry "
                "%zu: %.17g against %.17g); the compiler flags may change "
                "rounding",
                what, k, b[k], a[k]);
            return false;
        }
    return true;
}

/* Run the sweeps c compiles on both paths at x and compare: values,
 * gradients and, if c has them, the Lagrange block, the Jacobian block
 * and the Taylor sweep (the other sweeps stay interpreted on either
 * path). */
static int check(const tp_compiled *c, const double *xin,
                 tp_compile_info *info)
{
    const tp_tape *T = c->t;
    const int n = (int)T->n_indep, m = (int)T->n_out;
    const int nq = c->lagrange ? c->lcount : 0;
    /* per path: y[m], g[n]; L, dL/dt, dL/dq[nq], h[nq], M[nq x nq];
     * y[m], J[m x n]; y[m], y1[m], y2[m] */
    const size_t nl = c->lagrange ? 2 + 2 * (size_t)nq + (size_t)nq * nq : 0;
    const size_t nj = c->jacobian ? (size_t)m * (1 + (size_t)n) : 0;
    const size_t nt = c->taylor2 ? 3 * (size_t)m : 0;
    const size_t per = (size_t)m + (size_t)n + nl + nj + nt;
    tp_ws *w[2] = {NULL, NULL};
    double *x = calloc(2 * (size_t)n + (size_t)m + 2 * per + 1,
                       sizeof(double));
    double *wt, *dir, *r[2];
    int k, i, rc = -1;
    if (!x || tp_ws_new(&w[0], T, c->P > 0 ? c->P : 1, NULL) != TP_OK ||
        tp_ws_new(&w[1], T, c->P > 0 ? c->P : 1, NULL) != TP_OK) {
        say(info, "checking the compiled tape: out of memory");
        goto done;
    }
    if (tp_ws_set_compiled(w[1], c) != TP_OK) {
        say(info, "checking the compiled tape: %s", tp_ws_errmsg(w[1]));
        goto done;
    }
    wt = x + n;
    dir = wt + m;
    r[0] = dir + n;
    r[1] = r[0] + per;
    /* a default state inside most ops' domains, no two entries alike */
    for (i = 0; i < n; i++)
        x[i] = xin ? xin[i] : 0.3 + 0.05 * (double)(i % 11) + 1e-3 * i;
    for (i = 0; i < m; i++)
        wt[i] = 1.0 + 0.25 * (double)(i % 5);
    for (i = 0; i < n; i++)
        dir[i] = 0.7 - 0.1 * (double)(i % 13);
    for (k = 0; k < 2; k++) {
        double *y = r[k], *g = y + m, *L = g + n, *dt = L + 1, *gq = dt + 1,
               *h = gq + nq, *M = h + nq, *jy = y + m + n + nl,
               *J = jy + m, *ty = y + m + n + nl + nj;
        /* statuses may be TP_WARN_NONFINITE on both paths alike */
        if ((c->fwd0 && tp_eval(w[k], x, y) < 0) ||
            (c->rev1 && tp_vjp(w[k], x, wt, NULL, g) < 0) ||
            (c->lagrange &&
             tp_lagrange_t(w[k], x, c->lout, L, gq, dt, M, h) < 0) ||
            (c->jacobian && tp_jacobian(w[k], x, 0, n, jy, J) < 0) ||
            (c->taylor2 &&
             tp_taylor2(w[k], x, dir, ty, ty + m, ty + 2 * m) < 0)) {
            say(info, "checking the compiled tape: %s", tp_ws_errmsg(w[k]));
            goto done;
        }
    }
    if (same(r[0], r[1], (size_t)m, "values", info) &&
        same(r[0] + m, r[1] + m, (size_t)n, "gradient", info) &&
        same(r[0] + m + n, r[1] + m + n, nl, "Lagrange block", info) &&
        same(r[0] + m + n + nl, r[1] + m + n + nl, nj, "Jacobian block",
             info) &&
        same(r[0] + m + n + nl + nj, r[1] + m + n + nl + nj, nt,
             "Taylor sweep", info))
        rc = 0;
done:
    tp_ws_free(&w[0]);
    tp_ws_free(&w[1]);
    free(x);
    return rc;
}

/* ---- the public calls -------------------------------------------------- */

static int build(const char *dir, const char *base, const char *key,
                 const tp_sbuf *src, const char *cc, const char *flags,
                 int parts, tp_compile_info *info)
{
    static atomic_uint counter;
    char tc[PATH_LEN], tso[PATH_LEN], tsum[PATH_LEN], log[PATH_LEN];
    char so[PATH_LEN], sum[PATH_LEN], c[PATH_LEN], tb[PATH_LEN];
    char tbase[160];
    const unsigned id = atomic_fetch_add(&counter, 1u);
    int rc = -1;
    snprintf(tbase, sizeof tbase, "%.64s.%ld.%u.tmp", base, (long)getpid(),
             id);
    if (path_of(so, sizeof so, dir, base, ".so") != 0 ||
        path_of(sum, sizeof sum, dir, base, ".sum") != 0 ||
        path_of(c, sizeof c, dir, base, ".c") != 0 ||
        path_of(log, sizeof log, dir, base, ".log") != 0 ||
        path_of(tc, sizeof tc, dir, tbase, ".c") != 0 ||
        path_of(tb, sizeof tb, dir, tbase, "") != 0 ||
        path_of(tso, sizeof tso, dir, tbase, ".so") != 0 ||
        path_of(tsum, sizeof tsum, dir, tbase, ".sum") != 0) {
        say(info, "the cache directory's name is too long: %s", dir);
        return -1;
    }
    if (write_file(tc, src->p, src->len) != 0) {
        say(info, "cannot write %s: %s", tc, strerror(errno));
        goto done;
    }
    info->t_compile = now();
    if (tp__run_build(cc, flags, tc, tso, tb, parts, log, info->msg,
                      sizeof info->msg) != 0) {
        info->t_compile = now() - info->t_compile;
        goto done;
    }
    info->t_compile = now() - info->t_compile;
    /* the object first, its checksum last: a reader trusts only the pair */
    if (write_sum(tso, tsum, key) != 0 || rename(tso, so) != 0 ||
        rename(tsum, sum) != 0 || rename(tc, c) != 0) {
        say(info, "cannot store the compiled tape in %s: %s", dir,
            strerror(errno));
        goto done;
    }
    unlink(log);
    rc = 0;
done:
    unlink(tc);
    unlink(tso);
    unlink(tsum);
    return rc;
}

/* Ops from which a tape counts as large for building it (below). */
#define LARGE_TAPE 500u

/* How many compilers build t side by side: one part for about every 500
 * ops (a part's compiler takes about half a second for them at -O1; fewer
 * ops would not pay for the extra link), at most the jobs allowed. */
static int build_parts(const tp_tape *t, const tp_compile_opts *o)
{
    long jobs = o && o->jobs > 0 ? o->jobs : sysconf(_SC_NPROCESSORS_ONLN);
    long parts = 1 + (long)(t->n_ops / LARGE_TAPE);
    if (jobs < 1)
        jobs = 1;
    if (parts > jobs)
        parts = jobs;
    return parts > TP_MAX_PARTS ? TP_MAX_PARTS : (int)parts;
}

int tp_compile(const tp_tape *t, const tp_compile_opts *o,
               tp_compiled **out, tp_compile_info *info_out)
{
    tp_compile_info local, *info = info_out ? info_out : &local;
    const char *cc, *flags;
    char dir[PATH_LEN], base[64], key[33], so[PATH_LEN], sum[PATH_LEN],
        why[sizeof info->msg];
    tp_sbuf src = {0};
    tp_compiled *c = NULL;
    hash128 h;
    double t0;
    int have, rc, P, lout;
    unsigned sweeps;
    static const int format = TP_CODEGEN_FORMAT;

    memset(info, 0, sizeof *info);
    if (!out)
        return TP_ERR_NULL;
    *out = NULL;
    if (!t) {
        say(info, "tp_compile: the tape is NULL");
        return TP_ERR_NULL;
    }
    cc = o && o->cc && *o->cc ? o->cc : getenv("CC");
    if (!cc || !*cc)
        cc = "cc";
    flags = o && o->cflags ? o->cflags : getenv("AUTOEOM_CFLAGS");
    /* The generated code writes each slot once where it is first needed,
     * so the dead-store passes find next to nothing; on a large tape they
     * took a quarter of the compile time (50 links: 2.2 s of processor
     * time against 1.6 s; the code's instructions 0.2 % more). On small
     * tapes, where compiling is quick anyway, they stay (1 to 2.5 % fewer
     * instructions). */
    if (!flags)
        flags = t->n_ops >= LARGE_TAPE ? "-O1 -fno-dse -fno-tree-dse" : "-O1";
    if (cache_dir(o, dir, sizeof dir) != 0) {
        say(info, "no cache directory for compiled tapes (set "
                  "AUTOEOM_CACHE_DIR or HOME)");
        return TP_ERR_COMPILE;
    }
    t0 = now();
    P = o && o->max_dirs > 0 ? (o->max_dirs + TP_LANES - 1) / TP_LANES * TP_LANES
                             : 0;
    sweeps = o && o->sweeps ? o->sweeps
                            : TP_SWEEP_VALUES | TP_SWEEP_GRADIENTS;
    lout = o && (o->lagrange || (sweeps & TP_SWEEP_LAGRANGE))
               ? o->lagrange_out
               : -1;
    sweeps &= TP_SWEEP_VALUES | TP_SWEEP_GRADIENTS | TP_SWEEP_JACOBIAN |
              TP_SWEEP_TAYLOR2;
    if (o && (o->sweeps & ~(TP_SWEEP_VALUES | TP_SWEEP_GRADIENTS |
                            TP_SWEEP_LAGRANGE | TP_SWEEP_JACOBIAN |
                            TP_SWEEP_TAYLOR2))) {
        say(info, "tp_compile: sweeps has bits other than TP_SWEEP_VALUES, "
                  "_GRADIENTS, _LAGRANGE, _JACOBIAN and _TAYLOR2 (%#x)",
            o->sweeps);
        return TP_ERR_SIZE;
    }
    if ((sweeps & TP_SWEEP_JACOBIAN) && (int)t->n_indep > o->max_dirs) {
        say(info, "tp_compile: the Jacobian block needs max_dirs >= n_indep "
                  "(%u), max_dirs is %d",
            t->n_indep, o->max_dirs);
        return TP_ERR_SIZE;
    }
    if (lout >= 0 && (P == 0 || (uint32_t)lout >= t->n_out ||
                      (int)t->n_indep / 2 > P)) {
        say(info, "tp_compile: the Lagrange block needs max_dirs >= n_indep "
                  "/ 2 and an output of the tape");
        return TP_ERR_SIZE;
    }
    rc = tp__emit_c(t, P, lout, sweeps, &src);
    if (rc != TP_OK) {
        tp__sbuf_free(&src);
        say(info, rc == TP_ERR_NOMEM
                      ? "generating the compiled tape's source: out of memory"
                      : "tp_compile: the Lagrange block's directions (the "
                        "second half of the independents) are not whole "
                        "dependency groups");
        return rc;
    }
    hash_init(&h);
    hash_bytes(&h, &format, sizeof format);
    hash_bytes(&h, cc, strlen(cc) + 1);
    hash_bytes(&h, flags, strlen(flags) + 1);
    hash_bytes(&h, src.p, src.len);
    hash_hex(&h, key);
    tp__sbuf_printf(&src,
                    "#if TPC_PART == 0\n"
                    "TPC_EXPORT const char tpc_key[] = \"%s\";\n#endif\n",
                    key);
    info->t_emit = now() - t0;
    info->source_bytes = src.len;
    snprintf(base, sizeof base, "tp-%s", key);
    if (path_of(so, sizeof so, dir, base, ".so") != 0 ||
        path_of(sum, sizeof sum, dir, base, ".sum") != 0 ||
        strlen(so) >= sizeof info->path) {
        tp__sbuf_free(&src);
        say(info, "the cache directory's name is too long: %.400s", dir);
        return TP_ERR_COMPILE;
    }
    memcpy(info->path, so, strlen(so) + 1);
    c = calloc(1, sizeof *c);
    if (src.failed || !c) {
        rc = TP_ERR_NOMEM;
        say(info, "compiling the tape: out of memory");
        goto fail;
    }
    c->t = t;
    c->P = P;
    c->sweeps = sweeps;
    c->lout = lout;
    c->lfirst = c->lcount = (int)t->n_indep / 2;
    for (rc = c->lfirst; rc < c->lfirst + c->lcount; rc++)
        c->lmask |= 1u << t->group[rc];
    for (rc = 0; rc < (int)t->n_indep; rc++)
        c->jmask |= 1u << t->group[rc];
    if (make_dirs(dir) != 0) {
        say(info, "cannot create the cache directory %s: %s", dir,
            strerror(errno));
        rc = TP_ERR_COMPILE;
        goto fail;
    }
    have = entry_ok(so, sum, key, why, sizeof why);
    if (have == 1) {
        t0 = now();
        if (load(c, so, key, info) == 0) {
            info->t_load = now() - t0;
            t0 = now();
            if (check(c, o ? o->x : NULL, info) == 0) {
                info->t_check = now() - t0;
                info->cached = 1;
                goto done;
            }
            unload(c);
        }
        memcpy(why, info->msg, sizeof why);
        have = -1;
    }
    if (have == -1)
        info->rebuilt = 1;
    info->parts = build_parts(t, o);
    if (build(dir, base, key, &src, cc, flags, info->parts, info) != 0) {
        rc = TP_ERR_COMPILE;
        goto fail;
    }
    t0 = now();
    if (load(c, so, key, info) != 0) {
        rc = TP_ERR_COMPILE;
        goto fail;
    }
    info->t_load = now() - t0;
    t0 = now();
    if (check(c, o ? o->x : NULL, info) != 0) {
        unload(c);
        rc = TP_ERR_COMPILE;
        goto fail;
    }
    info->t_check = now() - t0;
    if (info->rebuilt)
        say(info, "rebuilt the cache entry %.200s: %.280s", so, why);
done:
    tp__sbuf_free(&src);
    *out = c;
    return TP_OK;
fail:
    tp__sbuf_free(&src);
    free(c);
    return rc;
}

void tp_compiled_free(tp_compiled **c)
{
    if (!c || !*c)
        return;
    unload(*c);
    free(*c);
    *c = NULL;
}

int tp_ws_set_compiled(tp_ws *ws, const tp_compiled *c)
{
    if (!ws)
        return TP_ERR_NULL;
    if (c && c->t != ws->t) {
        snprintf(ws->msg, sizeof ws->msg,
                 "tp_ws_set_compiled: the compiled tape was made from "
                 "another tape");
        return TP_ERR_FOREIGN;
    }
    if (c && c->P != 0 && c->P != ws->P) {
        snprintf(ws->msg, sizeof ws->msg,
                 "tp_ws_set_compiled: the compiled tape was made for %d "
                 "directions, the workspace has %d",
                 c->P, ws->P);
        return TP_ERR_SIZE;
    }
    if (c && c->lagrange && !ws->cat) {
        /* the Lagrange block's own adjoints and rows */
        const size_t n = ws->t->n_ops;
        ws->cat = tp__alloc(&ws->al, n * (size_t)ws->P * sizeof(double));
        ws->cadj = tp__alloc(&ws->al, n * sizeof(double));
        if (!ws->cat || !ws->cadj) {
            tp__free(&ws->al, ws->cat, n * (size_t)ws->P * sizeof(double));
            tp__free(&ws->al, ws->cadj, n * sizeof(double));
            ws->cat = ws->cadj = NULL;
            snprintf(ws->msg, sizeof ws->msg,
                     "tp_ws_set_compiled: out of memory");
            return TP_ERR_NOMEM;
        }
    }
    ws->cc = c;
    return TP_OK;
}

int tp_ws_compiled(const tp_ws *ws)
{
    return ws && ws->cc ? 1 : 0;
}
