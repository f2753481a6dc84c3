/* One instance of the hand plant FMU, independent of the FMI version.
 *
 * The FMI 2 and FMI 3 wrappers (fmi2_functions.c, fmi3_functions.c) translate their
 * calls into these functions, as the Modelica Association's Reference FMUs share one
 * model between both interfaces. An instance holds the hand's parameters, the packed
 * model, the plant state, the held inputs and the outputs; the plant steps at the
 * internal step ``dt`` and a communication step must be a whole number of them.
 *
 * Variables, by value reference (the exporter writes modelDescription.xml from the same
 * numbers): HH_VR_TIME (FMI 3's independent variable), the inputs tau (9) and f_ext (3),
 * the outputs (HH_N_OUTPUTS, in the output row's order) and the hand's numbers as
 * parameters (HH_HAND_PARAMS, in the hand vector's order).
 *
 * The default parameters come from the FMU's resources (HH_RESOURCE_FILE), written by the
 * exporter: so one compiled library serves every exported hand.
 */
#ifndef HIERHAND_FMU_INSTANCE_H
#define HIERHAND_FMU_INSTANCE_H

#include <stddef.h>

#include "hand.h"

enum {
    HH_VR_TIME = 0,
    HH_VR_TAU = 1, /* nine */
    HH_VR_F_EXT = 10, /* three */
    HH_VR_OUTPUT = 101, /* HH_N_OUTPUTS */
    HH_VR_PARAM = 1001 /* HH_HAND_PARAMS */
};
enum { HH_N_INPUTS = 12 };

/* Statuses, numbered as fmi2Status and fmi3Status both are. */
typedef enum {
    HH_STATUS_OK = 0,
    HH_STATUS_WARNING = 1,
    HH_STATUS_DISCARD = 2,
    HH_STATUS_ERROR = 3,
    HH_STATUS_FATAL = 4
} hh_status;

/* Log categories declared in modelDescription.xml. */
#define HH_LOG_EVENTS "logEvents"
#define HH_LOG_WARNING "logStatusWarning"
#define HH_LOG_ERROR "logStatusError"

#define HH_RESOURCE_FILE "hand_parameters.txt"

/* The host's logger; the wrapper adapts it to its FMI version's callback. */
typedef void (*hh_logger)(void *environment, const char *instance, hh_status status, const char *category,
                          const char *message);

typedef enum { HH_INSTANTIATED, HH_INITIALIZATION, HH_STEPPING, HH_TERMINATED, HH_FAILED } hh_phase;

typedef struct hh_instance {
    char *name;
    hh_logger log;
    void *environment;
    int log_events; /* logEvents enabled (errors and warnings are always logged) */
    char finger_names[HH_FINGERS][32];
    double defaults[HH_HAND_PARAMS]; /* from the resources, for reset */
    double hand[HH_HAND_PARAMS]; /* current parameter values */
    double dt; /* internal step, s */
    hh_model model;
    hh_work work;
    int model_current; /* model, state and outputs follow the current parameters */
    double *state;
    size_t state_size;
    double inputs[HH_N_INPUTS];
    double outputs[HH_N_OUTPUTS];
    double start_time;
    long long steps; /* internal steps since start_time */
    hh_phase phase;
} hh_instance;

/* A new instance, or NULL after logging why. ``token`` must equal the one in the
 * resources (the modelDescription's guid / instantiationToken); ``resource_dir`` is a
 * folder path. */
hh_instance *hh_instance_new(const char *name, const char *token, const char *resource_dir, hh_logger log,
                             void *environment, int logging_on);
void hh_instance_free(hh_instance *inst);

void hh_instance_log(const hh_instance *inst, hh_status status, const char *category, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* fmi2SetDebugLogging / fmi3SetDebugLogging: logEvents on when ``on`` and either no
 * categories or logEvents among them; an unknown category is a logged error. */
hh_status hh_instance_set_logging(hh_instance *inst, int on, size_t n, const char *const categories[]);

/* The folder of a file: URI ("file:///a/b/resources" or "file:/a/b"), percent-decoded,
 * into ``out``; 0 on success. */
int hh_path_from_uri(const char *uri, char *out, size_t size);

hh_status hh_instance_enter_initialization(hh_instance *inst, double start_time);
hh_status hh_instance_exit_initialization(hh_instance *inst);
hh_status hh_instance_get(hh_instance *inst, const unsigned int *vr, size_t n, double *values);
hh_status hh_instance_set(hh_instance *inst, const unsigned int *vr, size_t n, const double *values);
hh_status hh_instance_do_step(hh_instance *inst, double current_time, double step);
double hh_instance_time(const hh_instance *inst);
hh_status hh_instance_terminate(hh_instance *inst);
hh_status hh_instance_reset(hh_instance *inst);

/* FMU states: a snapshot of everything an instance computes with. The functions take
 * the FMI functions' arguments as they come (NULL pointers included: logged errors). */
typedef struct hh_snapshot hh_snapshot;
hh_status hh_instance_get_state(hh_instance *inst, hh_snapshot **snapshot); /* reuses *snapshot if set */
hh_status hh_instance_set_state(hh_instance *inst, const hh_snapshot *snapshot);
hh_status hh_snapshot_free(hh_snapshot **snapshot); /* frees *snapshot, sets it to NULL */
hh_status hh_snapshot_size(hh_instance *inst, const hh_snapshot *snapshot, size_t *size);
hh_status hh_snapshot_serialize(hh_instance *inst, const hh_snapshot *snapshot, unsigned char *bytes, size_t size);
hh_status hh_snapshot_deserialize(hh_instance *inst, const unsigned char *bytes, size_t size,
                                  hh_snapshot **snapshot);

#endif
