/* The FMI 3.0 functions the test FMUs do not provide. fmpy looks up every function of
 * the API when it loads an FMU, so they must exist; they are never called and report
 * fmi3Error (3). Defined without the FMI headers, so one generic signature serves all.
 * With TYPED_ACCESSORS the typed get/set functions that typed_fmi3.c defines are left out,
 * with MODEL_EXCHANGE the model-exchange functions (typed_fmi3.c, me_fmi3.c), with
 * SCHEDULED_EXECUTION those of scheduled execution (clocks_fmi3.c); NO_CO_SIMULATION adds the
 * co-simulation ones that an FMU without co-simulation lacks (me_fmi3.c, clocks_fmi3.c). */
#if defined(__GNUC__)
#define EXPORT __attribute__((visibility("default")))
#else
#define EXPORT
#endif
#define UNSUPPORTED(name) EXPORT int name(void) { return 3; }
UNSUPPORTED(fmi3DeserializeFMUState)
UNSUPPORTED(fmi3EnterConfigurationMode)
UNSUPPORTED(fmi3EnterStepMode)
UNSUPPORTED(fmi3EvaluateDiscreteStates)
UNSUPPORTED(fmi3ExitConfigurationMode)
UNSUPPORTED(fmi3FreeFMUState)
UNSUPPORTED(fmi3GetAdjointDerivative)
UNSUPPORTED(fmi3GetDirectionalDerivative)
UNSUPPORTED(fmi3GetFMUState)
UNSUPPORTED(fmi3GetIntervalFraction)
UNSUPPORTED(fmi3GetNumberOfVariableDependencies)
UNSUPPORTED(fmi3GetOutputDerivatives)
UNSUPPORTED(fmi3GetShiftDecimal)
UNSUPPORTED(fmi3GetShiftFraction)
UNSUPPORTED(fmi3GetString)
UNSUPPORTED(fmi3GetVariableDependencies)
UNSUPPORTED(fmi3SerializeFMUState)
UNSUPPORTED(fmi3SerializedFMUStateSize)
UNSUPPORTED(fmi3SetClock)
UNSUPPORTED(fmi3SetFMUState)
UNSUPPORTED(fmi3SetIntervalDecimal)
UNSUPPORTED(fmi3SetIntervalFraction)
UNSUPPORTED(fmi3SetShiftDecimal)
UNSUPPORTED(fmi3SetShiftFraction)
UNSUPPORTED(fmi3SetString)
#ifndef SCHEDULED_EXECUTION /* clocks_fmi3.c provides these */
UNSUPPORTED(fmi3ActivateModelPartition)
UNSUPPORTED(fmi3GetClock)
UNSUPPORTED(fmi3GetIntervalDecimal)
UNSUPPORTED(fmi3InstantiateScheduledExecution)
#endif
#ifndef MODEL_EXCHANGE /* the model-exchange FMUs provide these */
UNSUPPORTED(fmi3CompletedIntegratorStep)
UNSUPPORTED(fmi3EnterContinuousTimeMode)
UNSUPPORTED(fmi3EnterEventMode)
UNSUPPORTED(fmi3GetContinuousStateDerivatives)
UNSUPPORTED(fmi3GetContinuousStates)
UNSUPPORTED(fmi3GetEventIndicators)
UNSUPPORTED(fmi3GetNominalsOfContinuousStates)
UNSUPPORTED(fmi3GetNumberOfContinuousStates)
UNSUPPORTED(fmi3GetNumberOfEventIndicators)
UNSUPPORTED(fmi3InstantiateModelExchange)
UNSUPPORTED(fmi3SetContinuousStates)
UNSUPPORTED(fmi3SetTime)
UNSUPPORTED(fmi3UpdateDiscreteStates)
#endif
#ifdef NO_CO_SIMULATION /* me_fmi3.c: a model-exchange FMU only */
UNSUPPORTED(fmi3InstantiateCoSimulation)
UNSUPPORTED(fmi3DoStep)
#endif
#ifndef TYPED_ACCESSORS /* typed_fmi3.c provides these */
UNSUPPORTED(fmi3GetBinary)
UNSUPPORTED(fmi3GetInt16)
UNSUPPORTED(fmi3GetInt64)
UNSUPPORTED(fmi3GetInt8)
UNSUPPORTED(fmi3GetUInt16)
UNSUPPORTED(fmi3GetUInt32)
UNSUPPORTED(fmi3GetUInt64)
UNSUPPORTED(fmi3GetUInt8)
UNSUPPORTED(fmi3SetBinary)
UNSUPPORTED(fmi3SetFloat32)
UNSUPPORTED(fmi3SetInt16)
UNSUPPORTED(fmi3SetInt64)
UNSUPPORTED(fmi3SetInt8)
UNSUPPORTED(fmi3SetUInt16)
UNSUPPORTED(fmi3SetUInt32)
UNSUPPORTED(fmi3SetUInt64)
UNSUPPORTED(fmi3SetUInt8)
#endif
