/* Traces of the test FMU's code running, for the tests that check which commands run an
 * FMU's code (a diagram run) and which must not (validate, graph, fmu info).
 *
 * Compiled with first_order_fmi2.c and -DTRACE_RUNS -DMARKER_DIR='"/some/folder"': the
 * library writes MARKER_DIR/<its file name>.loaded from a constructor, that is as soon as
 * it is loaded, and MARKER_DIR/<its file name>.instantiated from fmi2Instantiate. The file
 * name is the FMU's model identifier, so one build serves FMUs of different identifiers.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdio.h>
#include <string.h>

void trace_run(const char *event) {
    Dl_info info;
    const char *name = "unknown";
    if (dladdr((void *)trace_run, &info) && info.dli_fname) {
        const char *slash = strrchr(info.dli_fname, '/');
        name = slash ? slash + 1 : info.dli_fname;
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/%s.%s", MARKER_DIR, name, event);
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(event, f);
        fclose(f);
    }
}

__attribute__((constructor)) static void loaded(void) { trace_run("loaded"); }
