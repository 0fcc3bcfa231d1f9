/* cli_stop.c - SIGTERM, SIGINT and SIGHUP as a request to stop
 * (cli_stop.h). The handler does the one thing a handler may: it stores
 * the signal's number in a sig_atomic_t, and gives the three their
 * default action back (sigaction is async-signal-safe), so a second
 * Ctrl-C ends a run that is stuck between safe points. SA_RESTART keeps
 * the writes in progress from failing with EINTR. A signal ignored when
 * the program starts (nohup ignores SIGHUP) stays ignored. */
#define _POSIX_C_SOURCE 200809L
#include "cli_stop.h"

#include <string.h>

volatile sig_atomic_t cli_stop_signal = 0;

static const int sigs[] = {SIGTERM, SIGINT, SIGHUP};
enum { NSIGS = sizeof sigs / sizeof sigs[0] };
static int caught[NSIGS]; /* installed here (not ignored at the start) */

static void on_signal(int sig)
{
    struct sigaction dfl;
    int k;
    cli_stop_signal = sig;
    memset(&dfl, 0, sizeof dfl);
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    for (k = 0; k < NSIGS; k++)
        if (caught[k])
            sigaction(sigs[k], &dfl, NULL);
}

void cli_stop_install(void)
{
    struct sigaction sa, old;
    int k;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sa.sa_flags = SA_RESTART;
    sigemptyset(&sa.sa_mask);
    for (k = 0; k < NSIGS; k++)
        sigaddset(&sa.sa_mask, sigs[k]);
    for (k = 0; k < NSIGS; k++) {
        if (sigaction(sigs[k], NULL, &old) != 0 || old.sa_handler == SIG_IGN)
            continue;
        caught[k] = 1;
        sigaction(sigs[k], &sa, NULL);
    }
}

const char *cli_stop_name(int sig)
{
    switch (sig) {
    case SIGTERM: return "SIGTERM";
    case SIGINT: return "SIGINT";
    case SIGHUP: return "SIGHUP";
    default: return "a signal";
    }
}
