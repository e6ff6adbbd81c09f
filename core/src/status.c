/* The statuses' messages (integrator.h). */
#include "thermofriction/integrator.h"

const char *tf_status_message(int status)
{
    switch (status) {
    case TF_OK: return "success";
    case TF_ERR_NONFINITE: return "the state or its derivative became NaN or infinite";
    case TF_ERR_STEP_UNDERFLOW: return "the step size fell below the resolution of the time variable";
    case TF_ERR_MAX_STEPS: return "the maximum number of steps was reached";
    case TF_ERR_BAD_ARGUMENT: return "invalid solver arguments";
    case TF_ERR_NO_MEMORY: return "out of memory";
    case TF_ERR_INTERRUPTED: return "interrupted";
    default: return "unknown error";
    }
}

