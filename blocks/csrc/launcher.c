/* A command's executable: SIGINT and SIGTERM blocked, then Python exec'd on its entry.
 *
 * A pip console script is a Python file, so a signal during the interpreter's own start
 * (its initialisation, ``site`` running the .pth files), before any of the program's code
 * can handle it, kills the process silently or prints a KeyboardInterrupt traceback. This
 * program blocks both signals first, and a blocked signal stays blocked, and pending, across
 * execve: a signal that comes while Python starts waits until the program's Python side
 * (blocks/process/stop.py, ``launch``) has installed its handlers and unblocks them, and then is one
 * line and the signal's exit code, as a signal at any later moment is.
 *
 * It runs ``PYTHON -P -c CODE ARGV0 ARGS...``, where CODE sets ``sys.argv`` to this
 * program's own and calls the entry, with the environment as it is; -P keeps the working
 * folder off the module path, so that a ``yaml.py`` there is not imported instead of the
 * real one. PYTHON is the first of LAUNCH_PYTHON_NAME, python3 and python found beside this
 * program's real location (a virtual environment's bin/, or /usr/local/bin), else
 * LAUNCH_PYTHON, the interpreter that built it. If none can be run it says so in one line,
 * naming each it tried, and exits 127 (none found) or 126 (one found but not runnable).
 *
 * The build defines (blocks/engine/native_sources.py, ``launcher_macros``):
 *   LAUNCH_PROGRAM      the command's name, which begins its messages ("hierhand")
 *   LAUNCH_MODULE       the module of its entry function ("hierhand.start")
 *   LAUNCH_FUNCTION     the entry function, called without arguments ("main")
 *   LAUNCH_PYTHON_NAME  the interpreter's versioned name ("python3.11")
 *   LAUNCH_PYTHON       the path of the interpreter that built it
 *   LAUNCH_HINT         a last word for the message when no Python can be run
 *
 * Plain C99 and POSIX; Linux for /proc/self/exe (elsewhere it goes to LAUNCH_PYTHON).
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#if !defined(LAUNCH_PROGRAM) || !defined(LAUNCH_MODULE) || !defined(LAUNCH_FUNCTION) || \
    !defined(LAUNCH_PYTHON_NAME) || !defined(LAUNCH_PYTHON) || !defined(LAUNCH_HINT)
#error "define LAUNCH_PROGRAM, LAUNCH_MODULE, LAUNCH_FUNCTION, LAUNCH_PYTHON_NAME, LAUNCH_PYTHON and LAUNCH_HINT"
#endif

#define CODE "import sys; del sys.argv[0]; from " LAUNCH_MODULE " import " LAUNCH_FUNCTION "; " \
             "sys.exit(" LAUNCH_FUNCTION "())"

#define PATH_SIZE 4096
#define MESSAGE_SIZE 8192
#define CANDIDATES 4

static const char *const NAMES[CANDIDATES - 1] = {LAUNCH_PYTHON_NAME, "python3", "python"};

/* The message so far, written to stderr in one write when complete. */
static char message[MESSAGE_SIZE];
static size_t message_length;

static void say(const char *format, ...) {
    va_list values;
    va_start(values, format);
    int n = vsnprintf(message + message_length, sizeof message - message_length, format, values);
    va_end(values);
    if (n < 0) return;
    message_length += (size_t)n;
    if (message_length >= sizeof message) message_length = sizeof message - 1;  /* truncated */
}

/* Writes the message and a newline to stderr and exits with ``code``; there is nothing to
 * do if stderr cannot be written. */
static void fail(int code) {
    if (message_length >= sizeof message - 1) message_length = sizeof message - 2;
    message[message_length++] = '\n';
    size_t done = 0;
    while (done < message_length) {
        ssize_t n = write(STDERR_FILENO, message + done, message_length - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        done += (size_t)n;
    }
    _exit(code);
}

/* The folder of this program's real file, with its final '/', or "" if it cannot be read. */
static void own_folder(char *folder, size_t size) {
    ssize_t n = readlink("/proc/self/exe", folder, size - 1);
    if (n <= 0 || (size_t)n >= size - 1) n = 0;  /* unreadable, or possibly truncated */
    folder[n] = '\0';
    char *slash = strrchr(folder, '/');
    if (slash == NULL) folder[0] = '\0';
    else slash[1] = '\0';
}

int main(int argc, char **argv) {
    sigset_t stops;
    if (sigemptyset(&stops) != 0 || sigaddset(&stops, SIGINT) != 0 || sigaddset(&stops, SIGTERM) != 0 ||
        sigprocmask(SIG_BLOCK, &stops, NULL) != 0) {
        say(LAUNCH_PROGRAM ": cannot block SIGINT and SIGTERM before Python starts: %s", strerror(errno));
        fail(126);
    }

    static char folder[PATH_SIZE];
    static char paths[CANDIDATES - 1][PATH_SIZE];
    const char *candidates[CANDIDATES];
    int count = 0;
    own_folder(folder, sizeof folder);
    if (folder[0] != '\0') {
        for (int i = 0; i < CANDIDATES - 1; i++) {
            int n = snprintf(paths[i], sizeof paths[i], "%s%s", folder, NAMES[i]);
            if (n > 0 && (size_t)n < sizeof paths[i]) candidates[count++] = paths[i];
        }
    }
    int listed = 0;  /* the interpreter that built it is the one beside it */
    for (int i = 0; i < count; i++) listed |= strcmp(candidates[i], LAUNCH_PYTHON) == 0;
    if (!listed) candidates[count++] = LAUNCH_PYTHON;

    /* PYTHON -P -c CODE ARGV0 ARGS... NULL */
    int given = argc > 0 ? argc : 1;
    char **args = malloc(((size_t)given + 5) * sizeof *args);
    if (args == NULL) {
        say(LAUNCH_PROGRAM ": cannot start Python: %s", strerror(errno));
        fail(126);
    }
    args[1] = "-P";
    args[2] = "-c";
    args[3] = CODE;
    args[4] = argc > 0 ? argv[0] : LAUNCH_PROGRAM;
    for (int i = 1; i < argc; i++) args[4 + i] = argv[i];
    args[4 + given] = NULL;

    int found = 0;
    say(LAUNCH_PROGRAM ": cannot start Python; tried");
    for (int i = 0; i < count; i++) {
        args[0] = (char *)candidates[i];
        execv(candidates[i], args);
        int error = errno;  /* execv returns only on failure */
        found |= error != ENOENT && error != ENOTDIR;
        say("%s %s (%s)", i == 0 ? "" : ",", candidates[i], strerror(error));
    }
    say("; %s", LAUNCH_HINT);
    fail(found ? 126 : 127);
    return 0;
}
