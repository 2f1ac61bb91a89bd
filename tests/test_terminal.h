/* test_terminal.h - runs rt with its stderr on a pseudo-terminal that the
 * test reads, so rt draws its progress bar there; and, for the tests of
 * Ctrl-C and SIGTERM, sends a signal when the bar shows that the render has
 * got far enough. The render's own progress decides when the signal goes,
 * never a sleep, so the branch a test asserts is the one taken.
 * Include after test_util.h, with _XOPEN_SOURCE 700 defined before any
 * header (posix_openpt).
 *
 *   char out[1 << 16];
 *   test_terminal_result r;
 *   // SIGINT once the bar reads "N/M spp" with N >= 4 (a whole pass done)
 *   test_terminal_signal at = {.sig = SIGINT, .unit = " spp", .at_least = 4};
 *   test_terminal_run(argv, &at, out, sizeof out, &r);   // argv[0]: the program
 *   // r.status: exit status (-1 when killed), r.signal: what killed it
 *
 * With at == NULL the program just runs. With at->again set, the signal is
 * sent a second time once the first has been delivered (read from
 * /proc/PID/status: no longer pending). test_terminal_run_io puts stdout
 * on the terminal too (as when a user runs rt in a shell), and
 * test_terminal_screen turns what the terminal got into the lines it
 * shows (carriage returns and erase-to-end-of-line applied):
 *
 *   test_terminal_run_io(argv, NULL, true, out, sizeof out, &r);
 *   char screen[1 << 16];
 *   test_terminal_screen(out, screen, sizeof screen);   // "line\nline\n..."
 */
#ifndef RT_TEST_TERMINAL_H
#define RT_TEST_TERMINAL_H

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdbool.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

typedef struct test_terminal_signal {
    int sig;          /* the signal to send */
    const char *unit; /* the bar's count to watch: " spp" (passes) or " tiles" */
    int at_least;     /* send once the bar reads "N/M<unit>" with N >= at_least */
    bool again;       /* then send it again once the first was delivered */
} test_terminal_signal;

typedef struct test_terminal_result {
    int status;       /* exit status, or -1 when killed by a signal */
    int signal;       /* the signal that killed it, else 0 */
    int signalled_at; /* the count the bar showed when the signal went, or -1 */
} test_terminal_result;

static inline double test_terminal_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The largest N of "N/M<unit>" in text, or -1 when there is none. */
static inline int test_terminal_bar_count(const char *text, const char *unit)
{
    int best = -1;
    size_t ul = strlen(unit);
    for (const char *u = strstr(text, unit); u; u = strstr(u + ul, unit)) {
        const char *p = u;
        while (p > text && p[-1] >= '0' && p[-1] <= '9')
            p--; /* M */
        if (p == u || p == text || p[-1] != '/')
            continue;
        const char *slash = --p;
        while (p > text && p[-1] >= '0' && p[-1] <= '9')
            p--; /* N */
        if (p == slash)
            continue;
        int n = atoi(p);
        best = n > best ? n : best;
    }
    return best;
}

/* True while signal sig is pending for process pid (not yet delivered). */
static inline bool test_terminal_pending(pid_t pid, int sig)
{
    char path[64], line[256];
    snprintf(path, sizeof path, "/proc/%d/status", (int)pid);
    FILE *f = fopen(path, "r");
    if (!f)
        return false; /* gone */
    bool pending = false;
    while (fgets(line, sizeof line, f))
        if (strncmp(line, "SigPnd:", 7) == 0 || strncmp(line, "ShdPnd:", 7) == 0) {
            unsigned long long mask = strtoull(line + 7, NULL, 16);
            pending |= (mask >> (sig - 1)) & 1u;
        }
    fclose(f);
    return pending;
}

/* The lines a terminal shows after receiving `raw`: '\r' goes back to the
 * line's start, "\033[K" erases from the cursor to the line's end, other
 * escape sequences are dropped, '\n' ends the line; each line of the
 * result ends with '\n' (the last one too, if not empty). */
static inline void test_terminal_screen(const char *raw, char *screen, size_t cap)
{
    char line[4096];
    size_t len = 0, col = 0, n = 0;
    screen[0] = 0;
    for (const char *c = raw;; c++) {
        if (*c == '\n' || (*c == 0 && len > 0)) {
            if (n + len + 2 < cap) {
                memcpy(screen + n, line, len);
                n += len;
                screen[n++] = '\n';
                screen[n] = 0;
            }
            len = col = 0;
        }
        if (*c == 0)
            break;
        if (*c == '\n')
            continue;
        if (*c == '\r') {
            col = 0;
        } else if (*c == '\033' && c[1] == '[') {
            const char *e = c + 2;
            while (*e && !((*e >= 'A' && *e <= 'Z') || (*e >= 'a' && *e <= 'z')))
                e++;
            if (*e == 'K' && e == c + 2)
                len = col; /* erase to the end of the line */
            c = *e ? e : e - 1;
        } else if (col < sizeof line) {
            line[col++] = *c;
            len = col > len ? col : len;
        }
    }
}

/* Runs argv (argv[0] the program) with stdin and stdout on /dev/null and
 * stderr on a new terminal; what the terminal shows goes into out
 * (NUL-terminated). Fails the test when the program runs over 120 s. */
static inline void test_terminal_run(const char *const *argv, const test_terminal_signal *at, char *out, size_t cap,
                                     test_terminal_result *r);

/* The same, with stdout on the terminal too when stdout_too. */
static inline void test_terminal_run_io(const char *const *argv, const test_terminal_signal *at, bool stdout_too,
                                        char *out, size_t cap, test_terminal_result *r)
{
    int master = posix_openpt(O_RDWR | O_NOCTTY);
    assert_true(master >= 0);
    assert_int_equal(grantpt(master), 0);
    assert_int_equal(unlockpt(master), 0);
    const char *slave = ptsname(master);
    assert_non_null(slave);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        int t = open(slave, O_RDWR | O_NOCTTY), null = open("/dev/null", O_RDWR);
        if (t < 0 || null < 0)
            _exit(127);
        dup2(null, 0);
        dup2(stdout_too ? t : null, 1);
        dup2(t, 2);
        close(master);
        execv(argv[0], (char *const *)argv);
        _exit(127);
    }
    size_t len = 0;
    out[0] = 0;
    int sent = 0, st = 0;
    r->signalled_at = -1;
    double t0 = test_terminal_now();
    for (;;) { /* read until the program has exited and the terminal is drained */
        struct pollfd pf = {master, POLLIN, 0};
        if (poll(&pf, 1, 20) == 1 && (pf.revents & POLLIN)) {
            ssize_t k = read(master, out + len, cap - 1 - len);
            if (k > 0) {
                len += (size_t)k;
                out[len] = 0;
            }
        }
        if (at && sent == 0) {
            int n = test_terminal_bar_count(out, at->unit);
            if (n >= at->at_least) {
                kill(pid, at->sig);
                sent = 1;
                r->signalled_at = n;
            }
        } else if (at && sent == 1 && at->again && !test_terminal_pending(pid, at->sig)) {
            kill(pid, at->sig);
            sent = 2;
        }
        if (waitpid(pid, &st, WNOHANG) == pid) {
            while (poll(&pf, 1, 100) == 1 && (pf.revents & POLLIN) && len < cap - 1) {
                ssize_t k = read(master, out + len, cap - 1 - len);
                if (k <= 0)
                    break;
                len += (size_t)k;
            }
            out[len] = 0;
            close(master);
            break;
        }
        if (test_terminal_now() - t0 > 120.0 || len >= cap - 1) {
            kill(pid, SIGKILL);
            waitpid(pid, &st, 0);
            close(master);
            fail_msg("%s on a terminal did not finish (%zu bytes read)", argv[0], len);
        }
    }
    r->status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    r->signal = WIFSIGNALED(st) ? WTERMSIG(st) : 0;
    if (r->status == 127)
        fail_msg("could not run %s", argv[0]);
    if (at && sent == 0)
        fail_msg("%s ended before its progress bar read %d%s: no signal was sent:\n%s", argv[0], at->at_least,
                 at->unit, out);
}

static inline void test_terminal_run(const char *const *argv, const test_terminal_signal *at, char *out, size_t cap,
                                     test_terminal_result *r)
{
    test_terminal_run_io(argv, at, false, out, cap, r);
}

#endif
