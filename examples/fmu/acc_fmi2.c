/* Time-gap ACC as an FMI 2.0 co-simulation FMU (the law: acc_law.h). Implements the
 * functions the testbed calls; build_fmu.py adds stubs that return fmi2Error for the rest. */
#include <stdlib.h>
#include "fmi2Functions.h"
#include "acc_law.h"

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                              fmi2String resources, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    AccState *s;
    (void)name; (void)guid; (void)resources; (void)functions; (void)visible; (void)loggingOn;
    if (type != fmi2CoSimulation) return NULL;
    s = (AccState *)calloc(1, sizeof(AccState));
    if (s) acc_defaults(s);
    return s;
}

void fmi2FreeInstance(fmi2Component c) { free(c); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined,
                               fmi2Real tolerance, fmi2Real startTime,
                               fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)c; (void)toleranceDefined; (void)tolerance; (void)startTime;
    (void)stopTimeDefined; (void)stopTime;
    return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c) { acc_defaults((AccState *)c); return fmi2OK; }

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[]) {
    size_t i;
    for (i = 0; i < nvr; i++) {
        if (vr[i] >= N_REALS) return fmi2Error;
        ((AccState *)c)->r[vr[i]] = value[i];
    }
    return fmi2OK;
}
fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[]) {
    size_t i;
    for (i = 0; i < nvr; i++) {
        if (vr[i] >= N_REALS) return fmi2Error;
        value[i] = ((AccState *)c)->r[vr[i]];
    }
    return fmi2OK;
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[]) {
    size_t i;
    for (i = 0; i < nvr; i++) {
        if (vr[i] != VR_HAS_LEAD) return fmi2Error;
        ((AccState *)c)->has_lead = value[i] != fmi2False;
    }
    return fmi2OK;
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[]) {
    size_t i;
    for (i = 0; i < nvr; i++) {
        if (vr[i] != VR_HAS_LEAD) return fmi2Error;
        value[i] = ((AccState *)c)->has_lead ? fmi2True : fmi2False;
    }
    return fmi2OK;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    (void)t; (void)noSetPrior;
    if (h <= 0) return fmi2Error;
    acc_step((AccState *)c, h);
    return fmi2OK;
}
