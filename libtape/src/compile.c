/* compile.c - compiled tapes: build the generated source (codegen.c) with
 * the system's C compiler into a shared object, keep it in a per-user
 * cache, load it, and check it against the interpreter before any sweep
 * uses it.
 *
 * The cache. An entry is named by a hash (SHA-256, sha256.c) of
 * everything that decides the machine code: the generated source (which
 * holds the tape and the kernels' text), the compiler that runs (the real
 * path PATH resolves its command to, the file's size, times and inode,
 * and what `CC --version` prints; compile_run.c), the command and its
 * flags, and the format. Beside the object NAME.so, NAME.sum records its
 * key, size and SHA-256, written after the object is complete.
 *
 * Who may write it. The cache is trusted as far as the user's own files
 * are, and no further: the directory (and each of the components the
 * library creates) must be owned by the effective user and writable by
 * no one else, and not be a symbolic link; each parent must be owned by
 * root or the user and writable by no one else unless sticky (/tmp). The
 * walk from the root opens one component at a time with O_NOFOLLOW and
 * checks what it opened (fstat), so a link swapped in between is refused
 * too. A directory that fails is not used: tp_compile says why
 * ("cache directory /tmp/x is writable by others: not used") and the tape
 * stays on the interpreter.
 *
 * Files. Everything the library writes is created exclusively
 * (O_CREAT | O_EXCL | O_NOFOLLOW) under a name no one can predict: a
 * build runs in a fresh folder of its own (mkdtemp: NAME.tmp-XXXXXX) and
 * its object, checksum and source are renamed into place, object first,
 * checksum last. A cache file is read through one descriptor opened with
 * O_NOFOLLOW | O_NONBLOCK (a FIFO does not hang the open) and fstat'ed:
 * a regular file of the user, writable by no one else, of bounded size
 * (MAX_SUM, MAX_OBJECT). The object is hashed as it is read through that
 * descriptor and copied at the same time into a fresh file of the cache
 * (NAME.ld-XXXXXX); only if the digest is the checksum's is that copy,
 * the very bytes hashed, given to dlopen (and unlinked at once). So no
 * constructor of a planted or corrupt object runs. After loading, the
 * object must report the same key and format, and its sweeps must give
 * the interpreter's results at one state (tp_compile_opts.x).
 * Temporaries of dead runs are never read, and are removed when older
 * than STALE_SECONDS.
 *
 * Not checked: the user's own processes (anything running as the user
 * can write the cache, as it can write ~/.bashrc), root, and what the
 * compiler itself reads (its headers, libraries and the environment).
 *
 * Nothing here fails a caller's computation: every failure is a status
 * and a message, and the tape keeps running on the interpreter.
 */
#define _GNU_SOURCE /* O_PATH, mkostemp */

#include <dirent.h>
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "codegen.h"

#define PATH_LEN 4096
/* The largest object and checksum file the cache reads (a 50-link
 * chain's object is about 2 MB). */
#define MAX_OBJECT ((off_t)64 << 20)
#define MAX_SUM 4096
/* A build folder or loader's copy older than this is a dead run's. */
#define STALE_SECONDS (24 * 3600)

/* the ancestors of the cache directory need only be searchable */
#if defined(O_PATH)
#define SEARCH_ONLY O_PATH
#else
#define SEARCH_ONLY O_RDONLY
#endif

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

/* The flags when none are given: -O1, for a large tape without the
 * dead-store passes (the generated code writes each slot once where it is
 * first needed, so they find next to nothing; on a large tape they took a
 * quarter of the compile time: 50 links 2.2 s of processor time against
 * 1.6 s, the code's instructions 0.2 % more; on small tapes, where
 * compiling is quick anyway, they stay: 1 to 2.5 % fewer instructions),
 * and for a large tape -mavx2 where this processor has AVX2: the
 * Lagrange block's strips then run as 4-wide vectors (codegen_lagrange.c;
 * 50 links 6 to 9 % faster; at 10 links, strips of 4, 10 % slower, hence
 * large tapes only), without FMA, so the rounding is the interpreter's.
 * The flags are part
 * of the cache key: an object built with them is never loaded where
 * they were not chosen. */
static const char *default_flags(bool large)
{
#if defined(__GNUC__) && defined(__x86_64__)
    __builtin_cpu_init();
    if (large && __builtin_cpu_supports("avx2"))
        return "-O1 -fno-dse -fno-tree-dse -mavx2";
#endif
    return large ? "-O1 -fno-dse -fno-tree-dse" : "-O1";
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- the cache directory ------------------------------------------------ */

/* mkdir -p with mode 0700 for the directories it creates (checked after,
 * by open_cache, like any other). */
static int make_dirs(const char *dir)
{
    char p[PATH_LEN];
    size_t k;
    if (strlen(dir) >= sizeof p) {
        errno = ENAMETOOLONG;
        return -1;
    }
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

/* The cache directory's name into out: 0, -1 if there is none, -2 if it
 * is too long. */
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
    return n > 0 && (size_t)n < len ? 0 : -2;
}

/* 0 if the folder st named path may hold the cache (last: it is the
 * cache directory; else one of its parents), else -1 and why. */
static int dir_safe(const struct stat *st, const char *path, bool last,
                    char *why, size_t len)
{
    const uid_t me = geteuid();
    const char *what = last ? "cache directory" : "the cache directory's "
                                                  "parent";
    if (!S_ISDIR(st->st_mode))
        snprintf(why, len, "%s %.300s is not a directory: not used", what,
                 path);
    else if (st->st_uid != me && (last || st->st_uid != 0))
        snprintf(why, len,
                 "%s %.300s is owned by uid %ld, not by this user (uid %ld): "
                 "not used",
                 what, path, (long)st->st_uid, (long)me);
    else if ((st->st_mode & (S_IWGRP | S_IWOTH)) &&
             (last || !(st->st_mode & S_ISVTX)))
        snprintf(why, len, "%s %.300s is writable by %s: not used", what,
                 path, st->st_mode & S_IWOTH ? "others" : "its group");
    else
        return 0;
    return -1;
}

/* Create (if need be) and open the cache directory dir: a descriptor, with
 * its real path in canon, or -1 and why. Each component of the real path
 * is opened from the root without following links and checked
 * (dir_safe), so the descriptor is the directory that was checked. */
static int open_cache(const char *dir, char *canon, size_t clen, char *why,
                      size_t len)
{
    char abs[PATH_LEN], part[PATH_LEN], *real;
    struct stat st;
    const char *p, *next;
    int fd, nfd, err;
    if (dir[0] != '/') {
        char cwd[PATH_LEN];
        const int n = getcwd(cwd, sizeof cwd)
                          ? snprintf(abs, sizeof abs, "%s/%s", cwd, dir)
                          : -1;
        if (n < 0 || (size_t)n >= sizeof abs) {
            snprintf(why, len, "cannot resolve the cache directory %.300s",
                     dir);
            return -1;
        }
    } else if (snprintf(abs, sizeof abs, "%s", dir) >= (int)sizeof abs) {
        snprintf(why, len, "the cache directory's name is too long: %.300s",
                 dir);
        return -1;
    }
    if (make_dirs(abs) != 0) {
        snprintf(why, len, "cannot create the cache directory %.300s: %s",
                 abs, strerror(errno));
        return -1;
    }
    if (lstat(abs, &st) == 0 && S_ISLNK(st.st_mode)) {
        snprintf(why, len, "cache directory %.300s is a symbolic link: not "
                           "used", abs);
        return -1;
    }
    real = realpath(abs, NULL);
    if (!real || strlen(real) >= clen) {
        snprintf(why, len, "cannot resolve the cache directory %.300s: %s",
                 abs, real ? "its name is too long" : strerror(errno));
        free(real);
        return -1;
    }
    memcpy(canon, real, strlen(real) + 1);
    free(real);
    fd = open("/", SEARCH_ONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0 || fstat(fd, &st) != 0 ||
        dir_safe(&st, "/", canon[1] == '\0', why, len) != 0) {
        if (fd < 0)
            snprintf(why, len, "cannot open /: %s", strerror(errno));
        if (fd >= 0)
            close(fd);
        return -1;
    }
    for (p = canon + 1; *p; p = next) {
        const size_t k = strcspn(p, "/");
        const bool last = p[k] == '\0' || p[k + 1] == '\0';
        char name[NAME_MAX + 1];
        next = p + k + (p[k] == '/');
        if (k > NAME_MAX) {
            close(fd);
            snprintf(why, len, "cannot open the cache directory %.300s: a "
                               "name is too long", canon);
            return -1;
        }
        memcpy(name, p, k);
        name[k] = '\0';
        snprintf(part, sizeof part, "%.*s", (int)(p + k - canon), canon);
        nfd = openat(fd, name,
                     (last ? O_RDONLY : SEARCH_ONLY) | O_DIRECTORY |
                         O_NOFOLLOW | O_CLOEXEC);
        err = errno;
        close(fd);
        if (nfd < 0) {
            snprintf(why, len, "cannot open the cache directory: %.300s: "
                               "%s", part,
                     err == ELOOP ? "a symbolic link" : strerror(err));
            return -1;
        }
        fd = nfd;
        if (fstat(fd, &st) != 0 || dir_safe(&st, part, last, why, len) != 0) {
            close(fd);
            return -1;
        }
    }
    return fd;
}

/* Remove the folder name of dfd and the files in it (a build folder). */
static void remove_tree(int dfd, const char *name)
{
    const int fd =
        openat(dfd, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    DIR *d = fd >= 0 ? fdopendir(fd) : NULL;
    struct dirent *e;
    if (fd >= 0 && !d)
        close(fd);
    if (d) {
        while ((e = readdir(d)) != NULL)
            if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0)
                unlinkat(fd, e->d_name, 0);
        closedir(d);
    }
    unlinkat(dfd, name, AT_REMOVEDIR);
}

/* 1 if name is one of the cache's temporaries (tp-KEY.tmp-XXXXXX, a
 * build folder; tp-KEY.ld-XXXXXX, a loader's copy). */
static bool temporary(const char *name)
{
    const char *dot = strrchr(name, '.');
    return strncmp(name, "tp-", 3) == 0 && dot &&
           (strncmp(dot, ".tmp-", 5) == 0 || strncmp(dot, ".ld-", 4) == 0) &&
           strlen(dot) == (dot[1] == 't' ? 11u : 10u);
}

/* Remove the temporaries of dead runs (older than STALE_SECONDS) from
 * the cache dfd; they are never read. */
static void clean_stale(int dfd)
{
    const int fd = openat(dfd, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    DIR *d = fd >= 0 ? fdopendir(fd) : NULL;
    const time_t old = time(NULL) - STALE_SECONDS;
    struct dirent *e;
    struct stat st;
    if (fd >= 0 && !d)
        close(fd);
    if (!d)
        return;
    while ((e = readdir(d)) != NULL)
        if (temporary(e->d_name) &&
            fstatat(dfd, e->d_name, &st, AT_SYMLINK_NOFOLLOW) == 0 &&
            st.st_mtime < old) {
            if (S_ISDIR(st.st_mode))
                remove_tree(dfd, e->d_name);
            else
                unlinkat(dfd, e->d_name, 0);
        }
    closedir(d);
}

/* ---- cache files --------------------------------------------------------- */

/* Open name in the folder dfd to read it as a cache file: following no
 * link and blocking on no FIFO; it must be a regular file of this user
 * that no one else may write, of at most max bytes. The descriptor (and
 * *st), or -1 and why (what names the file). */
static int open_owned(int dfd, const char *name, const char *what, off_t max,
                      struct stat *st, char *why, size_t len)
{
    const int fd =
        openat(dfd, name, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        snprintf(why, len, "%s %s", what,
                 errno == ENOENT ? "is missing"
                 : errno == ELOOP ? "is a symbolic link"
                                  : "cannot be opened");
        return -1;
    }
    if (fstat(fd, st) != 0)
        snprintf(why, len, "%s cannot be read: %s", what, strerror(errno));
    else if (!S_ISREG(st->st_mode))
        snprintf(why, len, "%s is not a regular file", what);
    else if (st->st_uid != geteuid())
        snprintf(why, len, "%s is owned by uid %ld, not by this user", what,
                 (long)st->st_uid);
    else if (st->st_mode & (S_IWGRP | S_IWOTH))
        snprintf(why, len, "%s is writable by others", what);
    else if (st->st_size > max)
        snprintf(why, len, "%s is larger than %lld %s", what,
                 (long long)(max >= (1 << 20) ? max >> 20 : max),
                 max >= (1 << 20) ? "MiB" : "bytes");
    else
        return fd;
    close(fd);
    return -1;
}

/* Create name in dfd (exclusively, 0600) holding p[n]: 0 or -1. */
static int write_new(int dfd, const char *name, const void *p, size_t n)
{
    const int fd = openat(dfd, name,
                          O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC,
                          0600);
    const char *c = p;
    int ok = fd >= 0;
    while (ok && n > 0) {
        const ssize_t w = write(fd, c, n);
        if (w < 0 && errno == EINTR)
            continue;
        ok = w > 0;
        c += ok ? w : 0;
        n -= ok ? (size_t)w : 0;
    }
    if (fd >= 0)
        ok = close(fd) == 0 && ok;
    return ok ? 0 : -1;
}

/* Read fd (a regular file of size bytes) to its end, hashing it (hex) and
 * copying it into a fresh file of the cache, canon/base.ld-XXXXXX (made
 * exclusively; its path in copy): 0, or -1 with no copy left and why. */
static int hash_copy(int fd, off_t size, const char *canon, const char *base,
                     char *copy, size_t clen, char hex[65], char *why,
                     size_t len)
{
    unsigned char buf[16384];
    tp_sha256 s;
    off_t total = 0;
    int out;
    if (snprintf(copy, clen, "%s/%s.ld-XXXXXX", canon, base) >= (int)clen) {
        snprintf(why, len, "the cache directory's name is too long");
        return -1;
    }
    out = mkostemp(copy, O_CLOEXEC);
    if (out < 0) {
        snprintf(why, len, "cannot copy the object to load it: %s",
                 strerror(errno));
        return -1;
    }
    tp__sha256_init(&s);
    for (;;) {
        const ssize_t r = read(fd, buf, sizeof buf);
        ssize_t w = 0, k;
        if (r < 0 && errno == EINTR)
            continue;
        if (r < 0 || total + r > size) {
            snprintf(why, len, "its object cannot be read, or grew");
            goto fail;
        }
        if (r == 0)
            break;
        total += r;
        tp__sha256_update(&s, buf, (size_t)r);
        while (w < r) {
            k = write(out, buf + w, (size_t)(r - w));
            if (k < 0 && errno == EINTR)
                continue;
            if (k <= 0) {
                snprintf(why, len, "cannot copy the object to load it: %s",
                         strerror(errno));
                goto fail;
            }
            w += k;
        }
    }
    if (total != size) {
        snprintf(why, len, "its object changed while it was read");
        goto fail;
    }
    if (close(out) != 0) {
        out = -1;
        snprintf(why, len, "cannot copy the object to load it: %s",
                 strerror(errno));
        goto fail;
    }
    tp__sha256_hex(&s, hex);
    return 0;
fail:
    if (out >= 0)
        close(out);
    unlink(copy);
    return -1;
}

#define SUM_MAGIC "autoeom compiled tape"

static int sum_text(char *out, size_t len, const char *key, long long bytes,
                    const char *hex)
{
    return snprintf(out, len, "%s %d\nkey %s\nbytes %lld\nsha256 %s\n",
                    SUM_MAGIC, TP_CODEGEN_FORMAT, key, bytes, hex);
}
/* ---- loading and checking ---------------------------------------------- */

static void unload(tp_compiled *c)
{
    if (c->dl)
        dlclose(c->dl);
    c->dl = NULL;
}

/* Load file (a verified private copy; unlinked here, loaded or not) as
 * the compiled form of c's tape with key; so names the entry in
 * messages. 0, or -1 with info->msg. */
static int load(tp_compiled *c, const char *file, const char *so,
                const char *key, tp_compile_info *info)
{
    const int *format;
    const uint32_t *nops;
    const size_t *kxs;
    const int *P;
    const unsigned *sweeps;
    const char *k;
    c->dl = dlopen(file, RTLD_NOW | RTLD_LOCAL);
    unlink(file);
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


/* ---- entries ------------------------------------------------------------- */

/* Load the entry base (base.so, base.sum in the cache dfd, real path
 * canon) into c and check it at x: 1 if it is in use; 0 if there is no
 * entry; -1 and why if there is one that must not be used. Nothing of
 * the object is loaded before its bytes match its checksum. */
static int load_entry(tp_compiled *c, int dfd, const char *canon,
                      const char *base, const char *key, const double *x,
                      tp_compile_info *info, char *why, size_t len)
{
    char so[80], sum[80], text[MAX_SUM + 1], expect[MAX_SUM + 1], hex[65],
        want[65], copy[PATH_LEN];
    struct stat st;
    long long bytes = -1;
    ssize_t r;
    size_t have = 0;
    int fd;
    snprintf(so, sizeof so, "%s.so", base);
    snprintf(sum, sizeof sum, "%s.sum", base);
    if (fstatat(dfd, so, &st, AT_SYMLINK_NOFOLLOW) != 0 && errno == ENOENT &&
        fstatat(dfd, sum, &st, AT_SYMLINK_NOFOLLOW) != 0 && errno == ENOENT)
        return 0;
    fd = open_owned(dfd, sum, "its checksum file", MAX_SUM, &st, why, len);
    if (fd < 0)
        return -1;
    while (have < MAX_SUM &&
           ((r = read(fd, text + have, MAX_SUM - have)) > 0 ||
            (r < 0 && errno == EINTR)))
        have += r > 0 ? (size_t)r : 0;
    close(fd);
    text[have] = '\0';
    sum_text(expect, sizeof expect, key, 0, "");
    *strstr(expect, "\nbytes ") = '\0';
    if (strncmp(text, SUM_MAGIC, strlen(SUM_MAGIC)) != 0) {
        snprintf(why, len, "its checksum file is not one of ours");
        return -1;
    }
    if (strncmp(text, expect, strlen(expect)) != 0) {
        snprintf(why, len, "it belongs to another tape or compiler");
        return -1;
    }
    if (sscanf(text + strlen(expect), "\nbytes %lld\nsha256 %64[0-9a-f]",
               &bytes, want) != 2 ||
        sum_text(expect, sizeof expect, key, bytes, want) >= MAX_SUM ||
        strcmp(text, expect) != 0) {
        snprintf(why, len, "its checksum file is not one of ours");
        return -1;
    }
    fd = open_owned(dfd, so, "its object", MAX_OBJECT, &st, why, len);
    if (fd < 0)
        return -1;
    if ((long long)st.st_size != bytes) {
        close(fd);
        snprintf(why, len, "its object does not match its checksum "
                           "(corrupt)");
        return -1;
    }
    r = hash_copy(fd, st.st_size, canon, base, copy, sizeof copy, hex, why,
                  len);
    close(fd);
    if (r != 0)
        return -1;
    if (strcmp(hex, want) != 0) {
        unlink(copy);
        snprintf(why, len, "its object does not match its checksum "
                           "(corrupt)");
        return -1;
    }
    if (load(c, copy, info->path, key, info) != 0) {
        snprintf(why, len, "%s", info->msg);
        return -1;
    }
    info->t_check = now();
    if (check(c, x, info) != 0) {
        unload(c);
        snprintf(why, len, "%s", info->msg);
        return -1;
    }
    info->t_check = now() - info->t_check;
    return 1;
}

/* Build src in a fresh folder of the cache (dfd, real path canon) with
 * exe run as cc and flags, store it as the entry base (object, checksum,
 * source) and leave a verified copy to load in copy: 0, or -1 with
 * info->msg (the compiler's messages kept as base.log). The build folder
 * is removed on every path. */
static int build(int dfd, const char *canon, const char *base,
                 const char *key, const tp_sbuf *src, const char *exe,
                 const char *cc, const char *flags, int parts, char *copy,
                 size_t clen, tp_compile_info *info)
{
    char wd[PATH_LEN], log_name[PATH_LEN], so[80], sum[80], csrc[80],
        logb[80], hex[65], text[MAX_SUM], why[256];
    const char *wname;
    struct stat st;
    int wfd = -1, fd, rc = -1;
    clean_stale(dfd);
    snprintf(so, sizeof so, "%s.so", base);
    snprintf(sum, sizeof sum, "%s.sum", base);
    snprintf(csrc, sizeof csrc, "%s.c", base);
    snprintf(logb, sizeof logb, "%s.log", base);
    if (snprintf(wd, sizeof wd, "%s/%s.tmp-XXXXXX", canon, base) >=
            (int)sizeof wd ||
        snprintf(log_name, sizeof log_name, "%s/%s", canon, logb) >=
            (int)sizeof log_name) {
        say(info, "the cache directory's name is too long: %.400s", canon);
        return -1;
    }
    if (!mkdtemp(wd)) {
        say(info, "cannot create a build folder in %.400s: %s", canon,
            strerror(errno));
        return -1;
    }
    wname = wd + strlen(canon) + 1;
    wfd = openat(dfd, wname, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (wfd < 0 || fstat(wfd, &st) != 0 ||
        dir_safe(&st, wd, true, why, sizeof why) != 0) {
        say(info, "the build folder %.400s is not ours", wd);
        goto done;
    }
    if (write_new(wfd, "src.c", src->p, src->len) != 0) {
        say(info, "cannot write %.400s/src.c: %s", wd, strerror(errno));
        goto done;
    }
    info->t_compile = now();
    if (tp__run_build(exe, cc, flags, wd, parts, log_name, info->msg,
                      sizeof info->msg) != 0) {
        info->t_compile = now() - info->t_compile;
        renameat(wfd, "log", dfd, logb); /* the compiler's messages */
        goto done;
    }
    info->t_compile = now() - info->t_compile;
    fd = open_owned(wfd, "out.so", "the compiled object", MAX_OBJECT, &st,
                    why, sizeof why);
    if (fd < 0) {
        say(info, "%s", why);
        goto done;
    }
    rc = hash_copy(fd, st.st_size, canon, base, copy, clen, hex, why,
                   sizeof why);
    close(fd);
    if (rc != 0) {
        say(info, "%s", why);
        goto done;
    }
    rc = -1;
    /* the object first, its checksum last: a reader trusts only the pair */
    if (write_new(wfd, "sum", text,
                  (size_t)sum_text(text, sizeof text, key,
                                   (long long)st.st_size, hex)) != 0 ||
        renameat(wfd, "out.so", dfd, so) != 0 ||
        renameat(wfd, "sum", dfd, sum) != 0 ||
        renameat(wfd, "src.c", dfd, csrc) != 0) {
        say(info, "cannot store the compiled tape in %.400s: %s", canon,
            strerror(errno));
        unlink(copy);
        goto done;
    }
    unlinkat(dfd, logb, 0);
    rc = 0;
done:
    if (wfd >= 0)
        close(wfd);
    remove_tree(dfd, wname);
    return rc;
}

/* ---- the public calls -------------------------------------------------- */

#define LARGE_TAPE 500u

/* How many compilers build a source of stmts statements (tp_sbuf.stmts:
 * a loop's body counted once) side by side: one part for about every 500
 * (a part's compiler takes about half a second for them at -O1; fewer
 * would not pay for the extra link and the kernels each part compiles
 * again), at most the jobs allowed. */
static int build_parts(size_t stmts, const tp_compile_opts *o)
{
    long jobs = o && o->jobs > 0 ? o->jobs : sysconf(_SC_NPROCESSORS_ONLN);
    long parts = 1 + (long)(stmts / LARGE_TAPE);
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
    char dir[PATH_LEN], canon[PATH_LEN], base[64], key[65], exe[PATH_LEN],
        ident[4096], copy[PATH_LEN], why[sizeof info->msg];
    tp_sbuf src = {0};
    tp_compiled *c = NULL;
    tp_sha256 h;
    double t0;
    int have, rc, P, lout, dfd = -1, where;
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
    if (!flags)
        flags = default_flags(t->n_ops >= LARGE_TAPE);
    where = cache_dir(o, dir, sizeof dir);
    if (where != 0) {
        say(info, where == -2 ? "the cache directory's name is longer than "
                                "%d bytes"
                              : "no cache directory for compiled tapes (set "
                                "AUTOEOM_CACHE_DIR or HOME)",
            PATH_LEN - 1);
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
    {
        const char *cg = getenv("AUTOEOM_CODEGEN");
        const bool straight = (o && o->straight) ||
                              (cg && strcmp(cg, "straight") == 0);
        rc = tp__emit_c(t, P, lout, sweeps, !straight, &src);
    }
    if (rc != TP_OK) {
        tp__sbuf_free(&src);
        say(info, rc == TP_ERR_NOMEM
                      ? "generating the compiled tape's source: out of memory"
                      : "tp_compile: the Lagrange block's directions (the "
                        "second half of the independents) are not whole "
                        "dependency groups");
        return rc;
    }
    /* the key: the compiler that runs, as it is now, and what it builds */
    if (tp__compiler_path(cc, exe, sizeof exe, info->msg, sizeof info->msg) !=
        0) {
        tp__sbuf_free(&src);
        return TP_ERR_COMPILE;
    }
    tp__compiler_identity(exe, cc, ident, sizeof ident);
    tp__sha256_init(&h);
    tp__sha256_update(&h, &format, sizeof format);
    tp__sha256_update(&h, cc, strlen(cc) + 1);
    tp__sha256_update(&h, ident, strlen(ident) + 1);
    tp__sha256_update(&h, flags, strlen(flags) + 1);
    tp__sha256_update(&h, src.p ? src.p : "", src.len);
    tp__sha256_hex(&h, key);
    key[32] = '\0'; /* 128 bits name an entry */
    tp__sbuf_printf(&src,
                    "#if TPC_PART == 0\n"
                    "TPC_EXPORT const char tpc_key[] = \"%s\";\n#endif\n",
                    key);
    info->t_emit = now() - t0;
    info->source_bytes = src.len;
    snprintf(base, sizeof base, "tp-%.32s", key);
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
    /* a directory that fails its checks is not used: the interpreter runs */
    dfd = open_cache(dir, canon, sizeof canon, info->msg, sizeof info->msg);
    if (dfd < 0) {
        rc = TP_ERR_COMPILE;
        goto fail;
    }
    if ((size_t)snprintf(info->path, sizeof info->path, "%s/%s.so", canon,
                         base) >= sizeof info->path) {
        say(info, "the cache directory's name is too long: %.400s", canon);
        rc = TP_ERR_COMPILE;
        goto fail;
    }
    t0 = now();
    have = load_entry(c, dfd, canon, base, key, o ? o->x : NULL, info, why,
                      sizeof why);
    if (have == 1) {
        info->t_load = now() - t0 - info->t_check;
        info->cached = 1;
        goto done;
    }
    if (have == -1)
        info->rebuilt = 1;
    info->parts = build_parts(src.stmts, o);
    if (build(dfd, canon, base, key, &src, exe, cc, flags, info->parts, copy,
              sizeof copy, info) != 0) {
        rc = TP_ERR_COMPILE;
        goto fail;
    }
    t0 = now();
    if (load(c, copy, info->path, key, info) != 0) {
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
        say(info, "rebuilt the cache entry %.200s: %.280s", info->path, why);
done:
    close(dfd);
    tp__sbuf_free(&src);
    *out = c;
    return TP_OK;
fail:
    if (dfd >= 0)
        close(dfd);
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
