/* The C tests' one check: counts a passed or failed condition, printing the file, line and message of a failed
 * one. Each test program prints "N passed, N failed" from these counters at its end. */
#ifndef THERMOFRICTION_TESTS_CHECK_H
#define THERMOFRICTION_TESTS_CHECK_H

#include <stdio.h>

static int passed, failed;

#define CHECK(cond, ...)                                                  \
    do {                                                                  \
        if (cond) passed++;                                               \
        else { failed++; printf("FAIL %s:%d: ", __FILE__, __LINE__);      \
               printf(__VA_ARGS__); printf("\n"); }                       \
    } while (0)

#endif
