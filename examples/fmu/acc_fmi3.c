/* Time-gap ACC as an FMI 3.0 co-simulation FMU (the law: acc_law.h). Implements the
 * functions the testbed calls; build_fmu.py adds stubs that return fmi3Error for the rest. */
#include <stdlib.h>
#include "fmi3Functions.h"
#include "acc_law.h"

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String name, fmi3String token, fmi3String resources, fmi3Boolean visible,
    fmi3Boolean loggingOn, fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
    const fmi3ValueReference required[], size_t nRequired, fmi3InstanceEnvironment env,
    fmi3LogMessageCallback log, fmi3IntermediateUpdateCallback update) {
    AccState *s;
    (void)name; (void)token; (void)resources; (void)visible; (void)loggingOn;
    (void)eventModeUsed; (void)earlyReturnAllowed; (void)required; (void)nRequired;
    (void)env; (void)log; (void)update;
    s = (AccState *)calloc(1, sizeof(AccState));
    if (s) acc_defaults(s);
    return s;
}

void fmi3FreeInstance(fmi3Instance c) { free(c); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean toleranceDefined,
                                       fmi3Float64 tolerance, fmi3Float64 startTime,
                                       fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    (void)c; (void)toleranceDefined; (void)tolerance; (void)startTime;
    (void)stopTimeDefined; (void)stopTime;
    return fmi3OK;
}
fmi3Status fmi3ExitInitializationMode(fmi3Instance c) { (void)c; return fmi3OK; }
fmi3Status fmi3Terminate(fmi3Instance c) { (void)c; return fmi3OK; }
fmi3Status fmi3Reset(fmi3Instance c) { acc_defaults((AccState *)c); return fmi3OK; }

fmi3Status fmi3SetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                          const fmi3Float64 values[], size_t nValues) {
    size_t i;
    if (nValues != nvr) return fmi3Error;
    for (i = 0; i < nvr; i++) {
        if (vr[i] >= N_REALS) return fmi3Error;
        ((AccState *)c)->r[vr[i]] = values[i];
    }
    return fmi3OK;
}
fmi3Status fmi3GetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                          fmi3Float64 values[], size_t nValues) {
    size_t i;
    if (nValues != nvr) return fmi3Error;
    for (i = 0; i < nvr; i++) {
        if (vr[i] >= N_REALS) return fmi3Error;
        values[i] = ((AccState *)c)->r[vr[i]];
    }
    return fmi3OK;
}
fmi3Status fmi3SetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                          const fmi3Boolean values[], size_t nValues) {
    size_t i;
    if (nValues != nvr) return fmi3Error;
    for (i = 0; i < nvr; i++) {
        if (vr[i] != VR_HAS_LEAD) return fmi3Error;
        ((AccState *)c)->has_lead = values[i] ? 1 : 0;
    }
    return fmi3OK;
}
fmi3Status fmi3GetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                          fmi3Boolean values[], size_t nValues) {
    size_t i;
    if (nValues != nvr) return fmi3Error;
    for (i = 0; i < nvr; i++) {
        if (vr[i] != VR_HAS_LEAD) return fmi3Error;
        values[i] = ((AccState *)c)->has_lead != 0;
    }
    return fmi3OK;
}

fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 t, fmi3Float64 h, fmi3Boolean noSetPrior,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                      fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    (void)noSetPrior;
    if (h <= 0) return fmi3Error;
    acc_step((AccState *)c, h);
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    *lastSuccessfulTime = t + h;
    return fmi3OK;
}
