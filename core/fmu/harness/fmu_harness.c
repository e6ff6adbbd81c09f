/* A minimal FMI 2.0 co-simulation importer for Windows (tests/test_fmu_windows.py runs it under Wine):
 * loads the FMU's win64 DLL with LoadLibrary, instantiates it, and for every line "drive temperature"
 * on standard input sets the inputs and takes one communication step of H seconds, printing
 * "time displacement velocity friction_force" after it. Exit status 0, or 1 with the reason on stderr.
 * Optional: IN and OUT, comma-separated value references of the inputs each line gives and of the
 * outputs printed after the time (default 0,1 and 2,3,4), e.g. for the temperature estimator's.
 *
 *   fmu_harness DLL RESOURCE_URI GUID H [IN OUT] < inputs.txt */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <windows.h>

#include "fmi2Functions.h"

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    fprintf(stderr, "[%s] %s\n", category, message);
}

static FARPROC get(HMODULE dll, const char *name)
{
    FARPROC f = GetProcAddress(dll, name);
    if (!f) {
        fprintf(stderr, "the DLL does not export %s\n", name);
        exit(1);
    }
    return f;
}

#define CHECK(call)                                                  \
    do {                                                             \
        if ((call) > fmi2Warning) {                                  \
            fprintf(stderr, "%s failed (line %d)\n", #call, __LINE__); \
            return 1;                                                \
        }                                                            \
    } while (0)

/* "2,3,4" into vr (at most 16); the count, or 0 if not such a list. */
static int vr_list(const char *s, fmi2ValueReference *vr)
{
    int n = 0;
    while (*s && n < 16) {
        char *end;
        unsigned long v = strtoul(s, &end, 10);
        if (end == s) return 0;
        vr[n++] = (fmi2ValueReference)v;
        s = *end == ',' ? end + 1 : end;
    }
    return *s ? 0 : n;
}

int main(int argc, char **argv)
{
    if (argc != 5 && argc != 7) {
        fprintf(stderr, "usage: fmu_harness DLL RESOURCE_URI GUID H [IN OUT] < inputs\n");
        return 1;
    }
    HMODULE dll = LoadLibraryA(argv[1]);
    if (!dll) {
        fprintf(stderr, "LoadLibrary(%s) failed: error %lu\n", argv[1], (unsigned long)GetLastError());
        return 1;
    }
    fmi2InstantiateTYPE *instantiate = (fmi2InstantiateTYPE *)get(dll, "fmi2Instantiate");
    fmi2SetupExperimentTYPE *setup = (fmi2SetupExperimentTYPE *)get(dll, "fmi2SetupExperiment");
    fmi2EnterInitializationModeTYPE *enter = (fmi2EnterInitializationModeTYPE *)get(dll, "fmi2EnterInitializationMode");
    fmi2ExitInitializationModeTYPE *exit_init = (fmi2ExitInitializationModeTYPE *)get(dll, "fmi2ExitInitializationMode");
    fmi2SetRealTYPE *set_real = (fmi2SetRealTYPE *)get(dll, "fmi2SetReal");
    fmi2GetRealTYPE *get_real = (fmi2GetRealTYPE *)get(dll, "fmi2GetReal");
    fmi2DoStepTYPE *do_step = (fmi2DoStepTYPE *)get(dll, "fmi2DoStep");
    fmi2TerminateTYPE *terminate = (fmi2TerminateTYPE *)get(dll, "fmi2Terminate");
    fmi2FreeInstanceTYPE *free_instance = (fmi2FreeInstanceTYPE *)get(dll, "fmi2FreeInstance");

    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = instantiate("harness", fmi2CoSimulation, argv[3], argv[2], &cb, fmi2False, fmi2False);
    if (!c) {
        fprintf(stderr, "fmi2Instantiate failed\n");
        return 1;
    }
    double h = atof(argv[4]), t = 0.0, in[16], out[16];
    fmi2ValueReference in_vr[16] = {0, 1}, out_vr[16] = {2, 3, 4};
    int n_in = argc == 7 ? vr_list(argv[5], in_vr) : 2, n_out = argc == 7 ? vr_list(argv[6], out_vr) : 3;
    if (n_in < 1 || n_out < 1) {
        fprintf(stderr, "IN and OUT: 1 to 16 comma-separated value references\n");
        return 1;
    }
    CHECK(setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0));
    CHECK(enter(c));
    CHECK(exit_init(c));
    for (;;) {
        int k = 0;
        while (k < n_in && scanf("%lf", &in[k]) == 1) k++;
        if (k < n_in) break;
        CHECK(set_real(c, in_vr, n_in, in));
        CHECK(do_step(c, t, h, fmi2True));
        t += h;
        CHECK(get_real(c, out_vr, n_out, out));
        printf("%.17g", t);
        for (k = 0; k < n_out; k++) printf(" %.17g", out[k]);
        printf("\n");
    }
    CHECK(terminate(c));
    free_instance(c);
    FreeLibrary(dll);
    return 0;
}
