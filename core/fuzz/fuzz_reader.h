/* The fuzz targets read their input as a stream of bytes: past its end, every byte is 0 (so that any
 * input, however short, describes a whole case). */
#ifndef THERMOFRICTION_FUZZ_READER_H
#define THERMOFRICTION_FUZZ_READER_H
#include <stddef.h>
#include <stdint.h>

typedef struct {
    const uint8_t *p;
    size_t n;
} reader;

static uint8_t byte(reader *r)
{
    if (!r->n) return 0;
    r->n--;
    return *r->p++;
}
#endif
