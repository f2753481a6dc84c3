/* A minimal FMI 2 co-simulation host without Python: loads an FMU's binary with dlopen,
 * optionally sets real variables, steps it and prints the requested variables each step.
 *
 *   fmi2_host LIBRARY GUID RESOURCE_URI STEP N_STEPS VR[,VR...] [VR=VALUE ...]
 *
 * Each output line: time, then the values, with 17 significant digits. Messages from the
 * FMU go to stderr as "[status] category: message". Exit code 0, or 1 on any failure. */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)env;
    va_list args;
    va_start(args, message);
    fprintf(stderr, "[%d] %s %s: ", (int)status, name, category);
    vfprintf(stderr, message, args);
    fputc('\n', stderr);
    va_end(args);
}

#define LOAD(name)                                                                                                  \
    name##TYPE *name = (name##TYPE *)dlsym(lib, #name);                                                             \
    if (name == NULL) {                                                                                             \
        fprintf(stderr, "missing %s\n", #name);                                                                     \
        return 1;                                                                                                   \
    }

int main(int argc, char **argv)
{
    if (argc < 7) {
        fprintf(stderr, "usage: %s LIBRARY GUID RESOURCE_URI STEP N_STEPS VR[,VR...] [VR=VALUE ...]\n", argv[0]);
        return 1;
    }
    void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (lib == NULL) {
        fprintf(stderr, "dlopen: %s\n", dlerror());
        return 1;
    }
    LOAD(fmi2Instantiate)
    LOAD(fmi2SetupExperiment)
    LOAD(fmi2EnterInitializationMode)
    LOAD(fmi2ExitInitializationMode)
    LOAD(fmi2SetReal)
    LOAD(fmi2GetReal)
    LOAD(fmi2DoStep)
    LOAD(fmi2Terminate)
    LOAD(fmi2FreeInstance)
    double step = atof(argv[4]);
    int n_steps = atoi(argv[5]);
    fmi2ValueReference vrs[256];
    size_t n_vr = 0;
    for (char *token = strtok(argv[6], ","); token != NULL && n_vr < 256; token = strtok(NULL, ","))
        vrs[n_vr++] = (fmi2ValueReference)strtoul(token, NULL, 10);
    fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
    fmi2Component c = fmi2Instantiate("host", fmi2CoSimulation, argv[2], argv[3], &callbacks, fmi2False, fmi2False);
    if (c == NULL)
        return 1;
    if (fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK)
        return 1;
    for (int i = 7; i < argc; i++) {
        fmi2ValueReference vr = (fmi2ValueReference)strtoul(argv[i], NULL, 10);
        char *eq = strchr(argv[i], '=');
        fmi2Real value = eq != NULL ? atof(eq + 1) : 0.0;
        if (fmi2SetReal(c, &vr, 1, &value) != fmi2OK)
            return 1;
    }
    if (fmi2EnterInitializationMode(c) != fmi2OK || fmi2ExitInitializationMode(c) != fmi2OK)
        return 1;
    fmi2Real values[256];
    for (int k = 0; k <= n_steps; k++) {
        if (k > 0 && fmi2DoStep(c, (k - 1) * step, step, fmi2True) != fmi2OK)
            return 1;
        if (fmi2GetReal(c, vrs, n_vr, values) != fmi2OK)
            return 1;
        printf("%.17g", k * step);
        for (size_t i = 0; i < n_vr; i++)
            printf(" %.17g", values[i]);
        printf("\n");
    }
    fmi2Terminate(c);
    fmi2FreeInstance(c);
    dlclose(lib);
    return 0;
}
