/* test_compile_cache.c - the compiled-tape cache against someone who can
 * write where it lives (tp_compile; docs/libtape.md, "The cache"). Public
 * API only; each case in a directory of its own under one scratch folder.
 *
 *   1. Directories: a cache directory writable by others or by its group,
 *      owned by another uid (12345, and a user made for the test), a
 *      symbolic link, or under a parent anyone may write is refused with
 *      a message that says why, and the tape gives the interpreter's
 *      numbers; a directory the library creates is 0700.
 *   2. Forged entries: another object (whose constructor leaves a mark)
 *      put in place of an entry with a checksum recomputed the old,
 *      unkeyed way; the same with a checksum of the new kind but files of
 *      another uid; the entry's object as a symbolic link: each refused
 *      and rebuilt, and the planted constructor never runs.
 *   3. Symbolic links at the names a build writes (the old predictable
 *      temporaries, the entry's object, checksum, source and log) point
 *      at a victim's file: it is unchanged.
 *   4. A FIFO in place of the checksum or the object does not hang (each
 *      compile in a child under a timeout); an object over 64 MiB (sparse)
 *      is refused before it is read.
 *   5. The key follows the compiler that runs: the same command "cc"
 *      resolving through PATH to another file gives another entry.
 *   6. Temporaries: none left after a build or a failed one; a dead run's
 *      (older than a day) removed, a recent one kept; a run killed
 *      mid-compile leaves no compiler running.
 */
#define _GNU_SOURCE

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "tape/tape.h"

#define NX 4

static char root[64]; /* the scratch folder */

static int rec_small(tp_rec *r, void *user)
{
    tp_val x[NX];
    int i;
    (void)user;
    for (i = 0; i < NX; i++)
        x[i] = tp_indep(r, i);
    tp_output(r, "L", tp_sub(r, tp_mul(r, tp_sqr(r, x[2]), tp_cos(r, x[0])),
                             tp_sin(r, x[1])));
    return 0;
}

static int rec_other(tp_rec *r, void *user)
{
    tp_val x[NX];
    int i;
    (void)user;
    for (i = 0; i < NX; i++)
        x[i] = tp_indep(r, i);
    tp_output(r, "L", tp_mul(r, tp_exp(r, x[3]), tp_sin(r, x[1])));
    return 0;
}

static tp_tape *record(tp_func f)
{
    unsigned char group[NX] = {0, 0, 1, 1};
    tp_rec *r = NULL;
    tp_tape *t = NULL;
    if (tp_recorder_new(&r, NX, group, NULL) != TP_OK ||
        tp_rec_run(r, NULL, f, NULL) != TP_OK ||
        tp_recorder_finish(r, &t) != TP_OK)
        t = NULL;
    tp_rec_free(&r);
    return t;
}

static const double X[NX] = {0.1, 0.2, 0.3, 0.4};
#define L_SMALL (0.09 * cos(0.1) - sin(0.2))

/* Compile t into dir (with cc, NULL for the default); the status and
 * info. The compiled tape, if any, gives the interpreter's value at X
 * (checked), then it is freed. */
static int compile_in(tp_tape *t, const char *dir, const char *cc,
                      tp_compile_info *info)
{
    tp_compile_opts o;
    tp_compiled *c = NULL;
    tp_ws *w = NULL, *v = NULL;
    double y = 0, z = 1;
    int st;
    memset(&o, 0, sizeof o);
    o.cache_dir = dir;
    o.cc = cc;
    st = tp_compile(t, &o, &c, info);
    CHECK(st == TP_OK ? c != NULL : c == NULL);
    CHECK_INT(tp_ws_new(&w, t, 1, NULL), TP_OK);
    CHECK_INT(tp_ws_new(&v, t, 1, NULL), TP_OK);
    if (c)
        CHECK_INT(tp_ws_set_compiled(w, c), TP_OK);
    CHECK_INT(tp_eval(w, X, &y), TP_OK);
    CHECK_INT(tp_eval(v, X, &z), TP_OK);
    CHECK(y == z);
    tp_ws_free(&w);
    tp_ws_free(&v);
    tp_compiled_free(&c);
    return st;
}

static void path(char *out, size_t len, const char *a, const char *b)
{
    snprintf(out, len, "%.300s/%.100s", a, b);
}

static void put(const char *file, const char *text)
{
    FILE *f = fopen(file, "wb");
    CHECK(f != NULL);
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

/* The file's first line (at most len - 1 bytes), "" if it cannot be read. */
static void get(const char *file, char *out, size_t len)
{
    FILE *f = fopen(file, "rb");
    size_t n = 0;
    if (f) {
        n = fread(out, 1, len - 1, f);
        fclose(f);
    }
    out[n] = '\0';
}

static int has(const char *s, const char *part)
{
    if (!strstr(s, part)) {
        fprintf(stderr, "  message: %s\n  lacks: %s\n", s, part);
        return 0;
    }
    return 1;
}

/* Names in dir that look like the cache's temporaries. */
static int temporaries(const char *dir)
{
    char cmd[512], line[256];
    FILE *p;
    int n = 0;
    snprintf(cmd, sizeof cmd,
             "ls -a '%s' | grep -E '\\.(tmp|ld)[-.]|\\.tmp\\.'", dir);
    p = popen(cmd, "r");
    while (p && fgets(line, sizeof line, p)) {
        fprintf(stderr, "  temporary left: %s", line);
        n++;
    }
    if (p)
        pclose(p);
    return n;
}

/* ---- 1. directories ------------------------------------------------------ */

static void refused(tp_tape *t, const char *dir, const char *why)
{
    tp_compile_info info;
    double y = 0;
    tp_ws *w = NULL;
    CHECK_INT(compile_in(t, dir, NULL, &info), TP_ERR_COMPILE);
    CHECK(has(info.msg, why));
    CHECK(has(info.msg, "not used"));
    /* the tape runs on: the interpreter's numbers */
    CHECK_INT(tp_ws_new(&w, t, 1, NULL), TP_OK);
    CHECK_INT(tp_eval(w, X, &y), TP_OK);
    CHECK_NEAR(y, L_SMALL, 1e-15);
    tp_ws_free(&w);
}

static void directories(tp_tape *t)
{
    char d[512], e[512], msg[800];
    struct stat st;
    tp_compile_info info;

    path(d, sizeof d, root, "world");
    CHECK_INT(mkdir(d, 0700), 0);
    CHECK_INT(chmod(d, 0777), 0);
    snprintf(msg, sizeof msg, "cache directory %.500s is writable by others", d);
    refused(t, d, msg);
    CHECK_INT(chmod(d, 0770), 0);
    refused(t, d, "is writable by its group");
    CHECK_INT(chmod(d, 0700), 0);
    CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);

    /* a symbolic link to a good directory */
    path(e, sizeof e, root, "link");
    CHECK_INT(symlink(d, e), 0);
    refused(t, e, "is a symbolic link");

    /* a parent anyone may write (not sticky) */
    path(d, sizeof d, root, "open");
    CHECK_INT(mkdir(d, 0700), 0);
    CHECK_INT(chmod(d, 0777), 0);
    path(e, sizeof e, d, "cache");
    refused(t, e, "parent");

    /* created by the library: 0700, each component */
    path(d, sizeof d, root, "made/deeper");
    CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);
    CHECK(stat(d, &st) == 0 && (st.st_mode & 0777) == 0700);
    path(d, sizeof d, root, "made");
    CHECK(stat(d, &st) == 0 && (st.st_mode & 0777) == 0700);

    /* owned by another uid */
    if (geteuid() != 0) {
        printf("skipped: a cache directory of another uid (needs root)\n");
        return;
    }
    path(d, sizeof d, root, "other");
    CHECK_INT(mkdir(d, 0700), 0);
    CHECK_INT(chown(d, 12345, 12345), 0);
    refused(t, d, "is owned by uid 12345, not by this user");
    {
        char user[32], cmd[200];
        snprintf(user, sizeof user, "tpcache%ld", (long)getpid() % 100000);
        snprintf(cmd, sizeof cmd,
                 "useradd -M -r -s /usr/sbin/nologin %s >/dev/null 2>&1",
                 user);
        if (system(cmd) != 0) {
            printf("skipped: a cache directory of a user made for the test "
                   "(useradd failed)\n");
            return;
        }
        path(d, sizeof d, root, "user");
        CHECK_INT(mkdir(d, 0700), 0);
        snprintf(cmd, sizeof cmd, "chown %s '%.150s'", user, d);
        CHECK_INT(system(cmd), 0);
        refused(t, d, "is owned by uid");
        snprintf(cmd, sizeof cmd, "userdel %s >/dev/null 2>&1", user);
        CHECK_INT(system(cmd), 0);
    }
}

/* ---- 2. forged entries ---------------------------------------------------- */

/* The checksum as the cache wrote it before it was keyed to the user's
 * files: FNV-1a lanes, anyone can recompute it. */
static void old_sum(const char *so, const char *sum, const char *key)
{
    FILE *f = fopen(so, "rb");
    unsigned long long a = 0xcbf29ce484222325ull, b = 0x84222325cbf29ce4ull,
                       n = 0, z, y;
    char text[300];
    int ch;
    CHECK(f != NULL);
    while (f && (ch = getc(f)) != EOF) {
        a = (a ^ (unsigned char)ch) * 0x100000001b3ull;
        b = (b ^ (unsigned long long)((unsigned char)ch + 0x5bu)) *
            0x100000001b3ull;
        n++;
    }
    if (f)
        fclose(f);
#define MIX(v)                                                             \
    (v = (v ^ (v >> 30)) * 0xbf58476d1ce4e5b9ull,                          \
     v = (v ^ (v >> 27)) * 0x94d049bb133111ebull, v ^ (v >> 31))
    z = a;
    y = b ^ a;
    z = MIX(z);
    y = MIX(y);
#undef MIX
    snprintf(text, sizeof text,
             "autoeom compiled tape 3\nkey %s\nbytes %llu\nhash %016llx%016llx\n",
             key, n, z, y);
    put(sum, text);
}

/* The entry of info: its object, checksum, source, log and key. */
typedef struct entry {
    char so[1100], sum[1100], c[1100], log[1100], key[40];
} entry;

static void entry_of(const tp_compile_info *info, entry *e)
{
    const char *base = strrchr(info->path, '/');
    const int stem = (int)strlen(info->path) - 3;
    snprintf(e->so, sizeof e->so, "%s", info->path);
    snprintf(e->sum, sizeof e->sum, "%.*s.sum", stem, info->path);
    snprintf(e->c, sizeof e->c, "%.*s.c", stem, info->path);
    snprintf(e->log, sizeof e->log, "%.*s.log", stem, info->path);
    snprintf(e->key, sizeof e->key, "%.32s", base ? base + 4 : "");
}

static int copy(const char *from, const char *to)
{
    char cmd[2400];
    snprintf(cmd, sizeof cmd, "cp '%s' '%s'", from, to);
    return system(cmd);
}

static void forged(tp_tape *t)
{
    char d[512], planted[512], mark[512], src[512], cmd[4096], text[900];
    tp_compile_info info;
    entry e;
    path(d, sizeof d, root, "forged");
    path(planted, sizeof planted, root, "planted.so");
    path(mark, sizeof mark, root, "planted-ran");
    path(src, sizeof src, root, "planted.c");
    snprintf(text, sizeof text,
             "#include <stdio.h>\n"
             "__attribute__((constructor)) static void ran(void)\n"
             "{ FILE *f = fopen(\"%s\", \"w\"); if (f) fclose(f); }\n"
             "const char tpc_key[] = \"nothing\";\n",
             mark);
    put(src, text);
    snprintf(cmd, sizeof cmd, "cc -shared -fPIC -o '%s' '%s'", planted, src);
    CHECK_INT(system(cmd), 0);

    CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);
    CHECK_INT(info.cached, 0);
    entry_of(&info, &e);
    /* the checksum holds the object's SHA-256, as sha256sum computes it */
    snprintf(cmd, sizeof cmd,
             "grep -q \"^sha256 $(sha256sum '%s' | cut -c1-64)$\" '%s'", e.so,
             e.sum);
    CHECK_INT(system(cmd), 0);

    /* another object, the checksum recomputed as it used to be */
    CHECK_INT(copy(planted, e.so), 0);
    old_sum(e.so, e.sum, e.key);
    CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);
    CHECK_INT(info.cached, 0);
    CHECK_INT(info.rebuilt, 1);
    CHECK(access(mark, F_OK) != 0);
    CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);
    CHECK_INT(info.cached, 1);

    /* a checksum of the new kind for the planted object, both files of
     * another uid */
    if (geteuid() == 0) {
        CHECK_INT(copy(planted, e.so), 0);
        snprintf(cmd, sizeof cmd,
                 "printf 'autoeom compiled tape 3\\nkey %s\\nbytes %%s\\n"
                 "sha256 %%s\\n' $(stat -c %%s '%s') "
                 "$(sha256sum '%s' | cut -c1-64) > '%s'",
                 e.key, e.so, e.so, e.sum);
        CHECK_INT(system(cmd), 0);
        CHECK_INT(chown(e.so, 12345, 12345), 0);
        CHECK_INT(chown(e.sum, 12345, 12345), 0);
        CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);
        CHECK_INT(info.rebuilt, 1);
        CHECK(has(info.msg, "owned by uid 12345"));
        CHECK(access(mark, F_OK) != 0);
    } else {
        printf("skipped: entry files of another uid (needs root)\n");
    }

    /* the object a symbolic link to a planted one */
    CHECK_INT(unlink(e.so), 0);
    CHECK_INT(symlink(planted, e.so), 0);
    old_sum(planted, e.sum, e.key);
    CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);
    CHECK_INT(info.rebuilt, 1);
    CHECK(access(mark, F_OK) != 0);
    CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);
    CHECK_INT(info.cached, 1);
    CHECK_INT(temporaries(d), 0);
}

/* ---- 3. symbolic links at the names a build writes ----------------------- */

static void links(tp_tape *t)
{
    char d[512], victim[512], name[1400], got[64];
    tp_compile_info info;
    entry e;
    int k;
    path(d, sizeof d, root, "links");
    path(victim, sizeof victim, root, "victim.txt");
    CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);
    entry_of(&info, &e);
    put(victim, "precious\n");
    /* the entry gone, a link at each name it writes, and at the old
     * predictable temporaries (tp-KEY.PID.ID.tmp.*) */
    unlink(e.so);
    unlink(e.sum);
    unlink(e.c);
    CHECK_INT(symlink(victim, e.so), 0);
    CHECK_INT(symlink(victim, e.sum), 0);
    CHECK_INT(symlink(victim, e.c), 0);
    CHECK_INT(symlink(victim, e.log), 0);
    for (k = 0; k < 64; k++) {
        static const char *ext[] = {".c", ".so", ".sum", ""};
        int j;
        for (j = 0; j < 4; j++) {
            snprintf(name, sizeof name, "%s/tp-%s.%ld.%d.tmp%s", d, e.key,
                     (long)getpid(), k, ext[j]);
            CHECK_INT(symlink(victim, name), 0);
        }
    }
    CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);
    CHECK_INT(info.cached, 0);
    get(victim, got, sizeof got);
    CHECK(strcmp(got, "precious\n") == 0);
    /* the links at the entry's names were replaced, not followed */
    CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);
    CHECK_INT(info.cached, 1);
    get(victim, got, sizeof got);
    CHECK(strcmp(got, "precious\n") == 0);
    /* a failed build (its log kept) does not follow the log's link */
    unlink(e.log);
    CHECK_INT(symlink(victim, e.log), 0);
    CHECK_INT(compile_in(t, d, "false", &info), TP_ERR_COMPILE);
    get(victim, got, sizeof got);
    CHECK(strcmp(got, "precious\n") == 0);
}

/* ---- 4. FIFOs and sizes ---------------------------------------------------- */

/* Compile t into dir in a child; its exit: 0 compiled and rebuilt, 1
 * otherwise, -1 if it took more than 60 s (killed). */
static int compile_in_child(tp_tape *t, const char *dir, char *msg,
                            size_t len)
{
    int fd[2], status = 0, k;
    pid_t pid;
    ssize_t n;
    CHECK_INT(pipe(fd), 0);
    pid = fork();
    if (pid == 0) {
        tp_compile_info info;
        int st = compile_in(t, dir, NULL, &info);
        close(fd[0]);
        if (write(fd[1], info.msg, strlen(info.msg) + 1) < 0)
            _exit(2);
        _exit(st == TP_OK && info.rebuilt == 1 ? 0 : 1);
    }
    close(fd[1]);
    for (k = 0; k < 600; k++) {
        const pid_t r = waitpid(pid, &status, WNOHANG);
        if (r == pid)
            break;
        usleep(100000);
    }
    msg[0] = '\0';
    if (k == 600) {
        fprintf(stderr, "  the compile did not end within 60 s\n");
        kill(pid, SIGKILL);
        waitpid(pid, &status, 0);
        close(fd[0]);
        return -1;
    }
    n = read(fd[0], msg, len - 1);
    msg[n > 0 ? n : 0] = '\0';
    close(fd[0]);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
}

static void fifos_and_sizes(tp_tape *t)
{
    char d[512], msg[600];
    tp_compile_info info;
    entry e;
    int fd;
    path(d, sizeof d, root, "fifo");
    CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);
    entry_of(&info, &e);
    /* a FIFO for the checksum */
    CHECK_INT(unlink(e.sum), 0);
    CHECK_INT(mkfifo(e.sum, 0600), 0);
    CHECK_INT(compile_in_child(t, d, msg, sizeof msg), 0);
    CHECK(has(msg, "not a regular file"));
    /* a FIFO for the object */
    CHECK_INT(unlink(e.so), 0);
    CHECK_INT(mkfifo(e.so, 0600), 0);
    CHECK_INT(compile_in_child(t, d, msg, sizeof msg), 0);
    CHECK(has(msg, "not a regular file"));
    /* an object of 100 MiB (sparse) beside its old checksum */
    unlink(e.so);
    fd = open(e.so, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    CHECK(fd >= 0);
    if (fd >= 0) {
        CHECK_INT(ftruncate(fd, (off_t)100 << 20), 0);
        close(fd);
    }
    CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);
    CHECK_INT(info.rebuilt, 1);
    CHECK(has(info.msg, "larger than 64 MiB"));
    CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);
    CHECK_INT(info.cached, 1);
}

/* ---- 5. the compiler that runs ------------------------------------------ */

static void compiler_key(tp_tape *t)
{
    char d[512], bin[512], cc[512], old_path[4096], new_path[4700];
    tp_compile_info a, b;
    const char *p = getenv("PATH");
    path(d, sizeof d, root, "key");
    path(bin, sizeof bin, root, "bin");
    path(cc, sizeof cc, bin, "cc");
    snprintf(old_path, sizeof old_path, "%s", p ? p : "/usr/bin:/bin");
    CHECK_INT(mkdir(bin, 0700), 0);
    /* another file called cc on PATH: a wrapper of the same compiler */
    put(cc, "#!/bin/sh\nPATH=\"${PATH#*:}\" exec cc \"$@\"\n");
    CHECK_INT(chmod(cc, 0700), 0);
    CHECK_INT(compile_in(t, d, "cc", &a), TP_OK);
    CHECK_INT(compile_in(t, d, "cc", &b), TP_OK);
    CHECK_INT(b.cached, 1);
    snprintf(new_path, sizeof new_path, "%.500s:%.4095s", bin, old_path);
    setenv("PATH", new_path, 1);
    CHECK_INT(compile_in(t, d, "cc", &b), TP_OK);
    CHECK_INT(b.cached, 0);
    CHECK(strcmp(a.path, b.path) != 0);
    setenv("PATH", old_path, 1);
    CHECK_INT(compile_in(t, d, "cc", &b), TP_OK);
    CHECK_INT(b.cached, 1);
    CHECK(strcmp(a.path, b.path) == 0);
}

/* ---- 6. temporaries ---------------------------------------------------------- */

static void old_file(const char *file, int dir)
{
    struct timespec ts[2];
    if (dir)
        CHECK_INT(mkdir(file, 0700), 0);
    else
        put(file, "x");
    clock_gettime(CLOCK_REALTIME, &ts[0]);
    ts[0].tv_sec -= 3 * 24 * 3600;
    ts[1] = ts[0];
    CHECK_INT(utimensat(AT_FDCWD, file, ts, AT_SYMLINK_NOFOLLOW), 0);
}

/* 1 if process pid is gone (or a zombie). */
static int gone(long pid)
{
    char file[64], text[256], *p;
    snprintf(file, sizeof file, "/proc/%ld/stat", pid);
    get(file, text, sizeof text);
    if (!text[0])
        return 1;
    p = strrchr(text, ')');
    return p && p[1] == ' ' && (p[2] == 'Z' || p[2] == 'X');
}

static void temps(tp_tape *t, tp_tape *t2)
{
    char d[512], f[2048], cc[512], pids[512], text[128];
    tp_compile_info info;
    pid_t pid;
    int k, status;
    long a = 0, b = 0;
    path(d, sizeof d, root, "temps");
    CHECK_INT(compile_in(t, d, NULL, &info), TP_OK);
    CHECK_INT(compile_in(t, d, "false", &info), TP_ERR_COMPILE);
    CHECK_INT(temporaries(d), 0);
    /* a dead run's build folder and loader's copy, and a recent one */
    snprintf(f, sizeof f, "%s/tp-0123456789abcdef0123456789abcdef.tmp-AbCdEf",
             d);
    old_file(f, 1);
    snprintf(f, sizeof f, "%s/tp-0123456789abcdef0123456789abcdef.ld-AbCdEf",
             d);
    old_file(f, 0);
    snprintf(f, sizeof f, "%s/tp-0123456789abcdef0123456789abcdef.tmp-Recent",
             d);
    CHECK_INT(mkdir(f, 0700), 0);
    CHECK_INT(compile_in(t2, d, NULL, &info), TP_OK);
    CHECK_INT(access(f, F_OK), 0);
    CHECK_INT(rmdir(f), 0);
    CHECK_INT(temporaries(d), 0);

    /* killed mid-compile: a compiler that starts a child and sleeps */
    path(cc, sizeof cc, root, "slowcc");
    path(pids, sizeof pids, root, "slowcc.pids");
    snprintf(f, sizeof f,
             "#!/bin/sh\n"
             "[ \"$1\" = --version ] && { echo slowcc 1; exit 0; }\n"
             "sleep 300 & echo $$ $! > '%s.new'; mv '%s.new' '%s'\n"
             "wait\n",
             pids, pids, pids);
    put(cc, f);
    CHECK_INT(chmod(cc, 0700), 0);
    pid = fork();
    if (pid == 0) {
        tp_compile_info i2;
        compile_in(t, d, cc, &i2);
        _exit(0);
    }
    for (k = 0; k < 300 && access(pids, F_OK) != 0; k++)
        usleep(100000);
    CHECK(k < 300);
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    get(pids, text, sizeof text);
    CHECK_INT(sscanf(text, "%ld %ld", &a, &b), 2);
    for (k = 0; k < 50 && a > 0 && !(gone(a) && gone(b)); k++)
        usleep(100000);
    CHECK(a > 0 && gone(a));
    CHECK(b > 0 && gone(b));
    if (a > 0 && !gone(a))
        kill((pid_t)a, SIGKILL);
    if (b > 0 && !gone(b))
        kill((pid_t)b, SIGKILL);
}

int main(void)
{
    char cmd[128];
    tp_tape *t = record(rec_small), *t2 = record(rec_other);
    snprintf(root, sizeof root, "/tmp/test-compile-cache-XXXXXX");
    CHECK(t != NULL && t2 != NULL);
    if (!t || !t2 || !mkdtemp(root)) {
        perror("test_compile_cache");
        return EXIT_FAILURE;
    }
    unsetenv("CC");
    unsetenv("AUTOEOM_CFLAGS");
    directories(t);
    forged(t);
    links(t);
    fifos_and_sizes(t);
    compiler_key(t);
    temps(t, t2);
    tp_tape_free(&t);
    tp_tape_free(&t2);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", root);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", root);
    CHECK_DONE();
}
