/* cli_stop.h - SIGTERM, SIGINT and SIGHUP as a request to stop: eom-run
 * and eom-ensemble finish what they are writing at the next safe point
 * (a whole row, the runs under way) and exit with 128 + the signal's
 * number, as a shell reports a process the signal ended. A second
 * signal of any of the three ends the process at once (the default
 * action), for a run that does not reach a safe point soon enough. */
#ifndef APPS_CLI_STOP_H
#define APPS_CLI_STOP_H

#include <signal.h>

/* Catch the three signals from now on (their handlers only set the flag
 * and restore the default action). */
void cli_stop_install(void);

/* The flag the handlers set: 0 until a signal arrives, then its number.
 * Poll it; it never goes back to 0. */
extern volatile sig_atomic_t cli_stop_signal;

/* "SIGTERM", "SIGINT" or "SIGHUP" for sig (other numbers: "a signal"). */
const char *cli_stop_name(int sig);

#endif /* APPS_CLI_STOP_H */
