/* thermofriction C core: everything in one include. */
#ifndef THERMOFRICTION_H
#define THERMOFRICTION_H
#include "thermofriction/status.h"
#include "thermofriction/waveform.h"
#include "thermofriction/law.h"
#include "thermofriction/thermal.h"
#include "thermofriction/friction.h"
#include "thermofriction/plant.h"
#include "thermofriction/integrator.h"
#include "thermofriction/sensitivity.h"
#include "thermofriction/realtime.h"
#include "thermofriction/control.h"
#include "thermofriction/estimator.h"
#include "thermofriction/prescribed.h"
#endif
