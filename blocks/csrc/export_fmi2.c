/* The FMI 2.0 co-simulation interface of an exported diagram FMU, over export_instance.h.
 *
 * Only the common and co-simulation functions are exported (a co-simulation-only FMU
 * needs no model-exchange functions). Every failure is logged through the host's logger
 * with a category and returns fmi2Error; nothing here aborts the host.
 */
#include <stdlib.h>

#include "fmi2Functions.h"
#include "export_instance.h"

typedef struct {
    blk_instance *inst;
    fmi2CallbackFunctions functions;
    int terminated; /* the diagram ended: fmi2GetBooleanStatus(fmi2Terminated) */
} component;

/* fmi2CallbackLogger takes a printf format. Hosts written in other languages often show it
 * as it is, so the message itself is passed as the format, its '%' doubled: both kinds of
 * host then show the text, and none can be made to read arguments that are not there. */
static void log_to_host(void *environment, const char *instance, blk_status status, const char *category,
                        const char *message)
{
    const component *c = environment;
    if (c->functions.logger == NULL)
        return;
    char format[2048];
    size_t n = 0;
    for (const char *p = message; *p != '\0' && n + 2 < sizeof format; p++) {
        if (*p == '%')
            format[n++] = '%';
        format[n++] = *p;
    }
    format[n] = '\0';
    c->functions.logger(c->functions.componentEnvironment, instance, (fmi2Status)status, category, format);
}

/* The instance of a component, or NULL when there is none to talk to. */
static blk_instance *instance_of(fmi2Component c)
{
    return c != NULL ? ((component *)c)->inst : NULL;
}

#define INSTANCE_OR_ERROR(c)                                                                                         \
    blk_instance *inst = instance_of(c);                                                                              \
    if (inst == NULL)                                                                                                \
    return fmi2Error

static fmi2Status no_variables(fmi2Component c, size_t nvr, const char *type)
{
    INSTANCE_OR_ERROR(c);
    if (nvr == 0)
        return fmi2OK;
    blk_instance_log(inst, BLK_STATUS_ERROR, BLK_LOG_ERROR, "this FMU has no %s variables", type);
    return fmi2Error;
}

static fmi2Status unsupported(fmi2Component c, const char *function)
{
    INSTANCE_OR_ERROR(c);
    blk_instance_log(inst, BLK_STATUS_ERROR, BLK_LOG_ERROR, "%s is not supported by this FMU", function);
    return fmi2Error;
}

const char *fmi2GetTypesPlatform(void)
{
    return fmi2TypesPlatform;
}

const char *fmi2GetVersion(void)
{
    return fmi2Version;
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    INSTANCE_OR_ERROR(c);
    return (fmi2Status)blk_instance_set_logging(inst, loggingOn, nCategories, categories);
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    (void)visible;
    if (functions == NULL)
        return NULL;
    component *c = calloc(1, sizeof *c);
    if (c == NULL)
        return NULL;
    c->functions = *functions;
    const char *name = instanceName != NULL ? instanceName : "";
    if (fmuType != fmi2CoSimulation) {
        log_to_host(c, name, BLK_STATUS_ERROR, BLK_LOG_ERROR, "this FMU supports co-simulation only");
        free(c);
        return NULL;
    }
    char folder[4096];
    const char *resources = NULL;
    if (fmuResourceLocation == NULL || blk_path_from_uri(fmuResourceLocation, folder, sizeof folder) != 0)
        log_to_host(c, name, BLK_STATUS_ERROR, BLK_LOG_ERROR, "the resource location is not a local file URI");
    else
        resources = folder;
    c->inst = resources != NULL ? blk_instance_new(name, fmuGUID, resources, log_to_host, c, loggingOn) : NULL;
    if (c->inst == NULL) {
        free(c);
        return NULL;
    }
    return c;
}

void fmi2FreeInstance(fmi2Component c)
{
    if (c == NULL)
        return;
    blk_instance_free(((component *)c)->inst);
    free(c);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    (void)toleranceDefined;
    (void)tolerance;
    INSTANCE_OR_ERROR(c);
    if (blk_instance_phase(inst) != BLK_INSTANTIATED) {
        blk_instance_log(inst, BLK_STATUS_ERROR, BLK_LOG_ERROR, "fmi2SetupExperiment must come before initialization");
        return fmi2Error;
    }
    return (fmi2Status)blk_instance_setup(inst, startTime, stopTimeDefined, stopTime);
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    INSTANCE_OR_ERROR(c);
    return (fmi2Status)blk_instance_enter_initialization(inst);
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    INSTANCE_OR_ERROR(c);
    return (fmi2Status)blk_instance_exit_initialization(inst);
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    INSTANCE_OR_ERROR(c);
    return (fmi2Status)blk_instance_terminate(inst);
}

fmi2Status fmi2Reset(fmi2Component c)
{
    INSTANCE_OR_ERROR(c);
    ((component *)c)->terminated = 0;
    return (fmi2Status)blk_instance_reset(inst);
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    INSTANCE_OR_ERROR(c);
    return (fmi2Status)blk_instance_get(inst, vr, nvr, value);
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[])
{
    (void)vr;
    (void)value;
    return no_variables(c, nvr, "Integer");
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[])
{
    (void)vr;
    (void)value;
    return no_variables(c, nvr, "Boolean");
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[])
{
    (void)vr;
    (void)value;
    return no_variables(c, nvr, "String");
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[])
{
    INSTANCE_OR_ERROR(c);
    return (fmi2Status)blk_instance_set(inst, vr, nvr, value);
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[])
{
    (void)vr;
    (void)value;
    return no_variables(c, nvr, "Integer");
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[])
{
    (void)vr;
    (void)value;
    return no_variables(c, nvr, "Boolean");
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[])
{
    (void)vr;
    (void)value;
    return no_variables(c, nvr, "String");
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    INSTANCE_OR_ERROR(c);
    return (fmi2Status)blk_instance_get_state(inst, (blk_snapshot **)FMUstate);
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate)
{
    INSTANCE_OR_ERROR(c);
    return (fmi2Status)blk_instance_set_state(inst, (const blk_snapshot *)FMUstate);
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate)
{
    (void)c;
    return (fmi2Status)blk_snapshot_free((blk_snapshot **)FMUstate);
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size)
{
    INSTANCE_OR_ERROR(c);
    return (fmi2Status)blk_snapshot_size(inst, (const blk_snapshot *)FMUstate, size);
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[], size_t size)
{
    INSTANCE_OR_ERROR(c);
    return (fmi2Status)blk_snapshot_serialize(inst, (const blk_snapshot *)FMUstate, (unsigned char *)serializedState,
                                             size);
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *FMUstate)
{
    INSTANCE_OR_ERROR(c);
    return (fmi2Status)blk_snapshot_deserialize(inst, (const unsigned char *)serializedState, size,
                                               (blk_snapshot **)FMUstate);
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[])
{
    (void)vUnknown_ref;
    (void)nUnknown;
    (void)vKnown_ref;
    (void)nKnown;
    (void)dvKnown;
    (void)dvUnknown;
    return unsupported(c, "fmi2GetDirectionalDerivative");
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    return unsupported(c, "fmi2SetRealInputDerivatives (inputs are held over a step)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    return unsupported(c, "fmi2GetRealOutputDerivatives");
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    INSTANCE_OR_ERROR(c);
    int terminated = 0;
    fmi2Status status =
        (fmi2Status)blk_instance_do_step(inst, currentCommunicationPoint, communicationStepSize, &terminated);
    ((component *)c)->terminated = terminated;
    /* the diagram ended during the step: fmi2Discard, with fmi2Terminated and the time it reached */
    return terminated && status == fmi2OK ? fmi2Discard : status;
}

fmi2Status fmi2CancelStep(fmi2Component c)
{
    return unsupported(c, "fmi2CancelStep (steps complete before fmi2DoStep returns)");
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    (void)s;
    (void)value;
    return unsupported(c, "fmi2GetStatus (steps complete before fmi2DoStep returns)");
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    INSTANCE_OR_ERROR(c);
    if (s != fmi2LastSuccessfulTime || value == NULL)
        return unsupported(c, "fmi2GetRealStatus of this kind");
    *value = blk_instance_time(inst);
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    (void)s;
    (void)value;
    return unsupported(c, "fmi2GetIntegerStatus");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    INSTANCE_OR_ERROR(c);
    if (s != fmi2Terminated || value == NULL)
        return unsupported(c, "fmi2GetBooleanStatus of this kind");
    *value = ((component *)c)->terminated ? fmi2True : fmi2False;
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    (void)s;
    (void)value;
    return unsupported(c, "fmi2GetStringStatus");
}
