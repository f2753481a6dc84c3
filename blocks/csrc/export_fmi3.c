/* The FMI 3.0 co-simulation and scheduled-execution interfaces of an exported diagram FMU,
 * over export_instance.h and export_scheduled.h.
 *
 * Every function of fmi3Functions.h is exported, as importers may look each one up; the
 * ones outside co-simulation without event mode and scheduled execution (model exchange,
 * setting clocks, configuration mode, derivatives) log why they are not available and
 * return fmi3Error. Every failure is logged through the host's logger with a category; nothing
 * here aborts the host.
 */
#include <stdlib.h>

#include "fmi3Functions.h"
#include "export_instance.h"
#include "export_scheduled.h"

typedef struct {
    blk_instance *inst;
    fmi3LogMessageCallback log_message;
    fmi3InstanceEnvironment environment;
} component;

static void log_to_host(void *environment, const char *instance, blk_status status, const char *category,
                        const char *message)
{
    (void)instance;
    const component *c = environment;
    if (c->log_message != NULL)
        c->log_message(c->environment, (fmi3Status)status, category, message);
}

static blk_instance *instance_of(fmi3Instance instance)
{
    return instance != NULL ? ((component *)instance)->inst : NULL;
}

#define INSTANCE_OR_ERROR(instance)                                                                                  \
    blk_instance *inst = instance_of(instance);                                                                       \
    if (inst == NULL)                                                                                                \
    return fmi3Error

static fmi3Status unsupported(fmi3Instance instance, const char *function)
{
    INSTANCE_OR_ERROR(instance);
    blk_instance_log(inst, BLK_STATUS_ERROR, BLK_LOG_ERROR, "%s is not supported by this co-simulation FMU", function);
    return fmi3Error;
}

static fmi3Status no_variables(fmi3Instance instance, size_t nValueReferences, const char *type)
{
    INSTANCE_OR_ERROR(instance);
    if (nValueReferences == 0)
        return fmi3OK;
    blk_instance_log(inst, BLK_STATUS_ERROR, BLK_LOG_ERROR, "this FMU has no %s variables", type);
    return fmi3Error;
}

/* -- common functions ---------------------------------------------------------------------- */

const char *fmi3GetVersion(void)
{
    return fmi3Version;
}

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[])
{
    INSTANCE_OR_ERROR(instance);
    return (fmi3Status)blk_instance_set_logging(inst, loggingOn, nCategories, categories);
}

static void refuse_interface(fmi3InstanceEnvironment environment, fmi3LogMessageCallback logMessage,
                             const char *interface)
{
    if (logMessage != NULL)
        logMessage(environment, fmi3Error, BLK_LOG_ERROR, interface);
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage)
{
    (void)instanceName;
    (void)instantiationToken;
    (void)resourcePath;
    (void)visible;
    (void)loggingOn;
    refuse_interface(instanceEnvironment, logMessage, "this FMU supports co-simulation only, not model exchange");
    return NULL;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate)
{
    (void)visible;
    (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables;
    (void)intermediateUpdate;
    if (eventModeUsed) {
        refuse_interface(instanceEnvironment, logMessage, "this FMU has no event mode (hasEventMode=\"false\")");
        return NULL;
    }
    if (nRequiredIntermediateVariables != 0) {
        refuse_interface(instanceEnvironment, logMessage, "this FMU provides no intermediate variables");
        return NULL;
    }
    component *c = calloc(1, sizeof *c);
    if (c == NULL)
        return NULL;
    c->log_message = logMessage;
    c->environment = instanceEnvironment;
    c->inst = blk_instance_new(instanceName, instantiationToken, resourcePath, log_to_host, c, loggingOn);
    if (c->inst == NULL) {
        free(c);
        return NULL;
    }
    return c;
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)visible;
    (void)clockUpdate; /* no output clocks, no countdown clocks */
    component *c = calloc(1, sizeof *c);
    if (c == NULL)
        return NULL;
    c->log_message = logMessage;
    c->environment = instanceEnvironment;
    c->inst = blk_instance_new_scheduled(instanceName, instantiationToken, resourcePath, log_to_host, c, loggingOn,
                                         lockPreemption, unlockPreemption);
    if (c->inst == NULL) {
        free(c);
        return NULL;
    }
    return c;
}

void fmi3FreeInstance(fmi3Instance instance)
{
    if (instance == NULL)
        return;
    blk_instance_free(((component *)instance)->inst);
    free(instance);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    (void)toleranceDefined;
    (void)tolerance;
    INSTANCE_OR_ERROR(instance);
    fmi3Status status = (fmi3Status)blk_instance_setup(inst, startTime, stopTimeDefined, stopTime);
    return status == fmi3OK ? (fmi3Status)blk_instance_enter_initialization(inst) : status;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance)
{
    INSTANCE_OR_ERROR(instance);
    return (fmi3Status)blk_instance_exit_initialization(inst);
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance)
{
    return unsupported(instance, "fmi3EnterEventMode (no event mode)");
}

fmi3Status fmi3Terminate(fmi3Instance instance)
{
    INSTANCE_OR_ERROR(instance);
    return (fmi3Status)blk_instance_terminate(inst);
}

fmi3Status fmi3Reset(fmi3Instance instance)
{
    INSTANCE_OR_ERROR(instance);
    return (fmi3Status)blk_instance_reset(inst);
}

/* -- values ------------------------------------------------------------------------------- */

static fmi3Status scalar_count(blk_instance *inst, size_t nValueReferences, size_t nValues)
{
    if (nValues == nValueReferences)
        return fmi3OK;
    blk_instance_log(inst, BLK_STATUS_ERROR, BLK_LOG_ERROR,
                    "%zu values for %zu value references: every variable of this FMU is a scalar", nValues,
                    nValueReferences);
    return fmi3Error;
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          fmi3Float64 values[], size_t nValues)
{
    INSTANCE_OR_ERROR(instance);
    if (scalar_count(inst, nValueReferences, nValues) != fmi3OK)
        return fmi3Error;
    return (fmi3Status)blk_instance_get(inst, valueReferences, nValueReferences, values);
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          const fmi3Float64 values[], size_t nValues)
{
    INSTANCE_OR_ERROR(instance);
    if (scalar_count(inst, nValueReferences, nValues) != fmi3OK)
        return fmi3Error;
    return (fmi3Status)blk_instance_set(inst, valueReferences, nValueReferences, values);
}

#define NO_VARIABLES_OF(NAME, TYPE)                                                                                  \
    fmi3Status fmi3Get##NAME(fmi3Instance instance, const fmi3ValueReference valueReferences[],                      \
                             size_t nValueReferences, TYPE values[], size_t nValues)                                 \
    {                                                                                                                \
        (void)valueReferences;                                                                                       \
        (void)values;                                                                                                \
        (void)nValues;                                                                                               \
        return no_variables(instance, nValueReferences, #NAME);                                                      \
    }                                                                                                                \
    fmi3Status fmi3Set##NAME(fmi3Instance instance, const fmi3ValueReference valueReferences[],                      \
                             size_t nValueReferences, const TYPE values[], size_t nValues)                           \
    {                                                                                                                \
        (void)valueReferences;                                                                                       \
        (void)values;                                                                                                \
        (void)nValues;                                                                                               \
        return no_variables(instance, nValueReferences, #NAME);                                                      \
    }

NO_VARIABLES_OF(Float32, fmi3Float32)
NO_VARIABLES_OF(Int8, fmi3Int8)
NO_VARIABLES_OF(UInt8, fmi3UInt8)
NO_VARIABLES_OF(Int16, fmi3Int16)
NO_VARIABLES_OF(UInt16, fmi3UInt16)
NO_VARIABLES_OF(Int32, fmi3Int32)
NO_VARIABLES_OF(UInt32, fmi3UInt32)
NO_VARIABLES_OF(Int64, fmi3Int64)
NO_VARIABLES_OF(UInt64, fmi3UInt64)
NO_VARIABLES_OF(Boolean, fmi3Boolean)
NO_VARIABLES_OF(String, fmi3String)

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues)
{
    (void)valueReferences;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    return no_variables(instance, nValueReferences, "Binary");
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const size_t valueSizes[], const fmi3Binary values[], size_t nValues)
{
    (void)valueReferences;
    (void)valueSizes;
    (void)values;
    (void)nValues;
    return no_variables(instance, nValueReferences, "Binary");
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Clock values[])
{
    (void)valueReferences;
    (void)values;
    return no_variables(instance, nValueReferences, "Clock");
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Clock values[])
{
    (void)valueReferences;
    (void)values;
    return no_variables(instance, nValueReferences, "Clock");
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                               size_t *nDependencies)
{
    (void)valueReference;
    (void)nDependencies;
    return unsupported(instance, "fmi3GetNumberOfVariableDependencies (see the ModelStructure)");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies)
{
    (void)dependent;
    (void)elementIndicesOfDependent;
    (void)independents;
    (void)elementIndicesOfIndependents;
    (void)dependencyKinds;
    (void)nDependencies;
    return unsupported(instance, "fmi3GetVariableDependencies (see the ModelStructure)");
}

/* -- FMU states ----------------------------------------------------------------------------- */

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    INSTANCE_OR_ERROR(instance);
    return (fmi3Status)blk_instance_get_state(inst, (blk_snapshot **)FMUState);
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState)
{
    INSTANCE_OR_ERROR(instance);
    return (fmi3Status)blk_instance_set_state(inst, (const blk_snapshot *)FMUState);
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    (void)instance;
    return (fmi3Status)blk_snapshot_free((blk_snapshot **)FMUState);
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size)
{
    INSTANCE_OR_ERROR(instance);
    return (fmi3Status)blk_snapshot_size(inst, (const blk_snapshot *)FMUState, size);
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[], size_t size)
{
    INSTANCE_OR_ERROR(instance);
    return (fmi3Status)blk_snapshot_serialize(inst, (const blk_snapshot *)FMUState, (unsigned char *)serializedState,
                                             size);
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState)
{
    INSTANCE_OR_ERROR(instance);
    return (fmi3Status)blk_snapshot_deserialize(inst, (const unsigned char *)serializedState, size,
                                               (blk_snapshot **)FMUState);
}

/* -- derivatives, configuration, clocks: not available ---------------------------------------- */

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    (void)unknowns;
    (void)nUnknowns;
    (void)knowns;
    (void)nKnowns;
    (void)seed;
    (void)nSeed;
    (void)sensitivity;
    (void)nSensitivity;
    return unsupported(instance, "fmi3GetDirectionalDerivative");
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    (void)unknowns;
    (void)nUnknowns;
    (void)knowns;
    (void)nKnowns;
    (void)seed;
    (void)nSeed;
    (void)sensitivity;
    (void)nSensitivity;
    return unsupported(instance, "fmi3GetAdjointDerivative");
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance)
{
    return unsupported(instance, "fmi3EnterConfigurationMode (no structural parameters)");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance)
{
    return unsupported(instance, "fmi3ExitConfigurationMode (no structural parameters)");
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, fmi3Float64 intervals[],
                                  fmi3IntervalQualifier qualifiers[])
{
    INSTANCE_OR_ERROR(instance);
    return (fmi3Status)blk_instance_clock_intervals(inst, valueReferences, nValueReferences, intervals, NULL, NULL,
                                                    (int *)qualifiers);
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[])
{
    INSTANCE_OR_ERROR(instance);
    return (fmi3Status)blk_instance_clock_intervals(inst, valueReferences, nValueReferences, NULL, counters,
                                                    resolutions, (int *)qualifiers);
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Float64 shifts[])
{
    INSTANCE_OR_ERROR(instance);
    return (fmi3Status)blk_instance_clock_shifts(inst, valueReferences, nValueReferences, shifts, NULL, NULL);
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
{
    INSTANCE_OR_ERROR(instance);
    return (fmi3Status)blk_instance_clock_shifts(inst, valueReferences, nValueReferences, NULL, counters, resolutions);
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, const fmi3Float64 intervals[])
{
    (void)valueReferences;
    (void)intervals;
    return no_variables(instance, nValueReferences, "Clock");
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3UInt64 counters[],
                                   const fmi3UInt64 resolutions[])
{
    (void)valueReferences;
    (void)counters;
    (void)resolutions;
    return no_variables(instance, nValueReferences, "Clock");
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Float64 shifts[])
{
    (void)valueReferences;
    (void)shifts;
    return no_variables(instance, nValueReferences, "Clock");
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    (void)valueReferences;
    (void)counters;
    (void)resolutions;
    return no_variables(instance, nValueReferences, "Clock");
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance)
{
    return unsupported(instance, "fmi3EvaluateDiscreteStates (no event mode)");
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime)
{
    (void)discreteStatesNeedUpdate;
    (void)terminateSimulation;
    (void)nominalsOfContinuousStatesChanged;
    (void)valuesOfContinuousStatesChanged;
    (void)nextEventTimeDefined;
    (void)nextEventTime;
    return unsupported(instance, "fmi3UpdateDiscreteStates (no event mode)");
}

/* -- model exchange: not available ---------------------------------------------------------- */

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance)
{
    return unsupported(instance, "fmi3EnterContinuousTimeMode (model exchange)");
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    (void)enterEventMode;
    (void)terminateSimulation;
    return unsupported(instance, "fmi3CompletedIntegratorStep (model exchange)");
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time)
{
    (void)time;
    return unsupported(instance, "fmi3SetTime (model exchange)");
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                   size_t nContinuousStates)
{
    (void)continuousStates;
    (void)nContinuousStates;
    return unsupported(instance, "fmi3SetContinuousStates (model exchange)");
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[],
                                             size_t nContinuousStates)
{
    (void)derivatives;
    (void)nContinuousStates;
    return unsupported(instance, "fmi3GetContinuousStateDerivatives (model exchange)");
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators)
{
    (void)eventIndicators;
    (void)nEventIndicators;
    return unsupported(instance, "fmi3GetEventIndicators (model exchange)");
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    (void)continuousStates;
    (void)nContinuousStates;
    return unsupported(instance, "fmi3GetContinuousStates (model exchange)");
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t nContinuousStates)
{
    (void)nominals;
    (void)nContinuousStates;
    return unsupported(instance, "fmi3GetNominalsOfContinuousStates (model exchange)");
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators)
{
    (void)nEventIndicators;
    return unsupported(instance, "fmi3GetNumberOfEventIndicators (model exchange)");
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates)
{
    (void)nContinuousStates;
    return unsupported(instance, "fmi3GetNumberOfContinuousStates (model exchange)");
}

/* -- co-simulation ---------------------------------------------------------------------------- */

fmi3Status fmi3EnterStepMode(fmi3Instance instance)
{
    return unsupported(instance, "fmi3EnterStepMode (no event mode: step mode follows initialization)");
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues)
{
    (void)valueReferences;
    (void)nValueReferences;
    (void)orders;
    (void)values;
    (void)nValues;
    return unsupported(instance, "fmi3GetOutputDerivatives");
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    INSTANCE_OR_ERROR(instance);
    int terminated = 0;
    fmi3Status status =
        (fmi3Status)blk_instance_do_step(inst, currentCommunicationPoint, communicationStepSize, &terminated);
    if (eventHandlingNeeded != NULL)
        *eventHandlingNeeded = fmi3False;
    if (terminateSimulation != NULL)
        *terminateSimulation = terminated ? fmi3True : fmi3False;
    if (earlyReturn != NULL)
        *earlyReturn = fmi3False;
    if (lastSuccessfulTime != NULL)
        *lastSuccessfulTime = blk_instance_time(inst);
    return status;
}

/* -- scheduled execution (export_scheduled.h) ---------------------------------------------------- */

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime)
{
    INSTANCE_OR_ERROR(instance);
    return (fmi3Status)blk_instance_activate(inst, clockReference, activationTime);
}
