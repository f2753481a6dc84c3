/* The FMI 2.0 functions the test FMUs do not provide. fmpy looks up every function of
 * the API when it loads an FMU, so they must exist; they are never called and report
 * fmi2Error (3). Defined without the FMI headers, so one generic signature serves all.
 * With STEP_STATUS the status functions that typed_fmi2.c defines are left out. */
#if defined(__GNUC__)
#define EXPORT __attribute__((visibility("default")))
#else
#define EXPORT
#endif
#define UNSUPPORTED(name) EXPORT int name(void) { return 3; }
UNSUPPORTED(fmi2GetFMUstate)
UNSUPPORTED(fmi2SetFMUstate)
UNSUPPORTED(fmi2FreeFMUstate)
UNSUPPORTED(fmi2SerializedFMUstateSize)
UNSUPPORTED(fmi2SerializeFMUstate)
UNSUPPORTED(fmi2DeSerializeFMUstate)
UNSUPPORTED(fmi2GetDirectionalDerivative)
UNSUPPORTED(fmi2SetRealInputDerivatives)
UNSUPPORTED(fmi2GetRealOutputDerivatives)
UNSUPPORTED(fmi2CancelStep)
UNSUPPORTED(fmi2GetStatus)
UNSUPPORTED(fmi2GetIntegerStatus)
UNSUPPORTED(fmi2GetStringStatus)
#ifndef STEP_STATUS
UNSUPPORTED(fmi2GetRealStatus)
UNSUPPORTED(fmi2GetBooleanStatus)
#endif
