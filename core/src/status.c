/* The statuses' messages and the error record (status.h). */
#include "thermofriction/status.h"

#include <math.h>
#include <string.h>

const char *tf_status_message(tf_status status)
{
    switch (status) {
    case TF_OK: return "success";
    case TF_ERR_NONFINITE: return "the state or its derivative became NaN or infinite";
    case TF_ERR_STEP_UNDERFLOW: return "the step size fell below the resolution of the time variable";
    case TF_ERR_MAX_STEPS: return "the maximum number of steps was reached";
    case TF_ERR_BAD_ARGUMENT: return "invalid argument";
    case TF_ERR_NO_MEMORY: return "out of memory";
    case TF_ERR_INTERRUPTED: return "interrupted";
    case TF_ERR_SINGULAR: return "singular matrix";
    default: return "unknown error";
    }
}

static void copy(char *dst, size_t size, const char *src)
{
    size_t n = src ? strlen(src) : 0;
    if (n >= size) n = size - 1;
    if (n) memcpy(dst, src, n);
    dst[n] = 0;
}

tf_status tf_error_set(tf_error *err, tf_status code, const char *where, const char *what, double t, long index)
{
    if (!err) return code;
    err->code = code;
    copy(err->what, sizeof err->what, what);
    copy(err->where, sizeof err->where, where);
    err->t = t;
    err->index = index;
    return code;
}
