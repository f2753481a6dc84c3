/* One instance of the hand plant FMU: parameters, initialization, stepping, FMU states.
 * See fmu_instance.h. */
#include "fmu_instance.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STEP_TOLERANCE 1e-6 /* a communication step may miss n * dt by this many internal steps */
#define MAX_STEPS_PER_CALL 1e12

static const char *PHASE_NAMES[] = {"instantiated", "initialization mode", "step mode", "terminated", "failed"};

void hh_instance_log(const hh_instance *inst, hh_status status, const char *category, const char *format, ...)
{
    if (inst == NULL || inst->log == NULL)
        return;
    if (status == HH_STATUS_OK && !inst->log_events)
        return;
    char message[1024];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    inst->log(inst->environment, inst->name, status, category, message);
}

#define LOG_ERROR(inst, ...) hh_instance_log((inst), HH_STATUS_ERROR, HH_LOG_ERROR, __VA_ARGS__)
#define LOG_EVENT(inst, ...) hh_instance_log((inst), HH_STATUS_OK, HH_LOG_EVENTS, __VA_ARGS__)

hh_status hh_instance_set_logging(hh_instance *inst, int on, size_t n, const char *const categories[])
{
    int events = n == 0;
    for (size_t i = 0; i < n; i++) {
        if (categories == NULL || categories[i] == NULL)
            continue;
        if (strcmp(categories[i], HH_LOG_EVENTS) == 0)
            events = 1;
        else if (strcmp(categories[i], HH_LOG_WARNING) != 0 && strcmp(categories[i], HH_LOG_ERROR) != 0) {
            LOG_ERROR(inst, "unknown log category '%s' (this FMU has %s, %s, %s)", categories[i], HH_LOG_EVENTS,
                      HH_LOG_WARNING, HH_LOG_ERROR);
            return HH_STATUS_ERROR;
        }
    }
    inst->log_events = on && events;
    return HH_STATUS_OK;
}

/* -- resources ----------------------------------------------------------------------------- */

int hh_path_from_uri(const char *uri, char *out, size_t size)
{
    const char *p = uri;
    if (strncmp(p, "file:", 5) == 0) {
        p += 5;
        if (strncmp(p, "///", 3) == 0)
            p += 2; /* file:///path */
        else if (strncmp(p, "//localhost/", 12) == 0)
            p += 11; /* file://localhost/path */
        else if (strncmp(p, "//", 2) == 0)
            return -1; /* a remote host */
    }
    size_t n = 0;
    while (*p != '\0') {
        char c = *p++;
        if (c == '%' && isxdigit((unsigned char)p[0]) && isxdigit((unsigned char)p[1])) {
            char hex[3] = {p[0], p[1], '\0'};
            c = (char)strtol(hex, NULL, 16);
            p += 2;
        }
        if (n + 1 >= size)
            return -1;
        out[n++] = c;
    }
    out[n] = '\0';
    return n > 0 ? 0 : -1;
}

/* A double written as the 16 hex digits of its IEEE 754 bits (exact, locale-free). */
static int parse_hex_double(const char *text, double *out)
{
    uint64_t bits = 0;
    int digits = 0;
    for (; isxdigit((unsigned char)*text); text++, digits++) {
        int c = tolower((unsigned char)*text);
        bits = (bits << 4) | (uint64_t)(c <= '9' ? c - '0' : c - 'a' + 10);
    }
    if (digits != 16)
        return -1;
    memcpy(out, &bits, sizeof *out);
    return 0;
}

static char *trim(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    size_t n = strlen(s);
    while (n > 0 && isspace((unsigned char)s[n - 1]))
        s[--n] = '\0';
    return s;
}

static void read_finger_names(hh_instance *inst, const char *value)
{
    for (int f = 0; f < HH_FINGERS; f++) {
        while (isspace((unsigned char)*value))
            value++;
        size_t n = 0;
        while (value[n] != '\0' && !isspace((unsigned char)value[n]))
            n++;
        if (n == 0 || n >= sizeof inst->finger_names[f])
            return;
        memcpy(inst->finger_names[f], value, n);
        inst->finger_names[f][n] = '\0';
        value += n;
    }
}

/* Read HH_RESOURCE_FILE: token, internal step, finger names and every hand number. */
static int read_resources(hh_instance *inst, const char *token, const char *folder)
{
    char path[4096];
    size_t len = strlen(folder);
    const char *sep = len > 0 && folder[len - 1] == '/' ? "" : "/";
    if ((size_t)snprintf(path, sizeof path, "%s%s%s", folder, sep, HH_RESOURCE_FILE) >= sizeof path) {
        LOG_ERROR(inst, "the resource folder path is too long: %s", folder);
        return -1;
    }
    FILE *file = fopen(path, "r");
    if (file == NULL) {
        LOG_ERROR(inst, "cannot open %s: the FMU's resources are missing or unreadable", path);
        return -1;
    }
    char line[512];
    int params = 0, line_no = 0, ok = 1, have_token = 0, have_dt = 0;
    while (ok && fgets(line, sizeof line, file) != NULL) {
        line_no++;
        char *key = trim(line);
        if (*key == '\0' || *key == '#')
            continue;
        char *value = key;
        while (*value != '\0' && !isspace((unsigned char)*value))
            value++;
        if (*value != '\0')
            *value++ = '\0';
        value = trim(value);
        if (strcmp(key, "token") == 0) {
            have_token = 1;
            if (token != NULL && strcmp(value, token) != 0) {
                LOG_ERROR(inst, "instantiation token '%s' does not match this FMU's '%s' (%s)", token, value, path);
                ok = 0;
            }
            continue;
        }
        if (strcmp(key, "dt") == 0)
            ok = have_dt = parse_hex_double(value, &inst->dt) == 0 && inst->dt > 0.0 && isfinite(inst->dt);
        else if (strcmp(key, "finger_names") == 0)
            read_finger_names(inst, value);
        else if (params < HH_HAND_PARAMS && strcmp(key, hh_hand_param_name(params)) == 0)
            ok = parse_hex_double(value, &inst->defaults[params++]) == 0;
        else
            ok = 0;
        if (!ok)
            LOG_ERROR(inst, "%s:%d: cannot read '%s' (expected %s)", path, line_no, key,
                      params < HH_HAND_PARAMS ? hh_hand_param_name(params) : "nothing more");
    }
    fclose(file);
    if (ok && (params != HH_HAND_PARAMS || !have_token || !have_dt)) {
        LOG_ERROR(inst, "%s is incomplete: %d of %d parameters%s%s", path, params, HH_HAND_PARAMS,
                  have_token ? "" : ", no token", have_dt ? "" : ", no dt");
        ok = 0;
    }
    return ok ? 0 : -1;
}

/* -- lifecycle ------------------------------------------------------------------------------ */

hh_instance *hh_instance_new(const char *name, const char *token, const char *resource_dir, hh_logger log,
                             void *environment, int logging_on)
{
    hh_instance *inst = calloc(1, sizeof *inst);
    if (inst == NULL) {
        if (log != NULL)
            log(environment, name, HH_STATUS_ERROR, HH_LOG_ERROR, "out of memory");
        return NULL;
    }
    inst->name = malloc(strlen(name != NULL ? name : "") + 1);
    if (inst->name == NULL) {
        free(inst);
        return NULL;
    }
    strcpy(inst->name, name != NULL ? name : "");
    inst->log = log;
    inst->environment = environment;
    inst->log_events = logging_on != 0;
    for (int f = 0; f < HH_FINGERS; f++)
        snprintf(inst->finger_names[f], sizeof inst->finger_names[f], "finger %d", f + 1);
    if (resource_dir == NULL || read_resources(inst, token, resource_dir) != 0) {
        if (resource_dir == NULL)
            LOG_ERROR(inst, "no resource location was given: the FMU needs its resources folder");
        hh_instance_free(inst);
        return NULL;
    }
    memcpy(inst->hand, inst->defaults, sizeof inst->hand);
    inst->phase = HH_INSTANTIATED;
    LOG_EVENT(inst, "instantiated (internal step %g s)", inst->dt);
    return inst;
}

static void release_model(hh_instance *inst)
{
    hh_work_free(&inst->work);
    free(inst->state);
    inst->state = NULL;
    inst->state_size = 0;
    inst->model_current = 0;
}

void hh_instance_free(hh_instance *inst)
{
    if (inst == NULL)
        return;
    release_model(inst);
    free(inst->name);
    free(inst);
}

static void report_parameter(void *context, int param, const char *text)
{
    hh_instance *inst = context;
    LOG_ERROR(inst, "invalid parameter: %s %s", hh_hand_param_name(param), text);
}

/* Log a plant failure; 'step' says whether t is the time of the step that failed (its
 * start, as HandPlant reports it) or of the state that was evaluated. */
static void describe_failure(const hh_instance *inst, int code, int which, double t, int step)
{
    char when[64];
    snprintf(when, sizeof when, "%s t=%.10g s", step ? "in the step at" : "at", t);
    static const char *axes[] = {"x", "y", "theta"}, *rates[] = {"vx", "vy", "omega"};
    const char *finger = inst->finger_names[(which / 3) % HH_FINGERS];
    switch (code) {
    case HH_ERR_PENETRATION:
        LOG_ERROR(inst,
                  "contact penetration deeper than the fingertip radius %s: the %s tip centre is inside "
                  "the object; the contact is too soft for the forces or the step too large",
                  when, inst->finger_names[which % HH_FINGERS]);
        break;
    case HH_ERR_Q:
        LOG_ERROR(inst, "non-finite value %s: joint angle q[%d] (%s joint %d) is not finite", when, which + 1,
                  finger, which % 3 + 1);
        break;
    case HH_ERR_QD:
        LOG_ERROR(inst, "non-finite value %s: joint velocity qd[%d] (%s joint %d) is not finite", when,
                  which + 1, finger, which % 3 + 1);
        break;
    case HH_ERR_OBJ:
        LOG_ERROR(inst, "non-finite value %s: object pose obj[%d] (%s) is not finite", when, which + 1,
                  axes[which % 3]);
        break;
    case HH_ERR_OBJ_VEL:
        LOG_ERROR(inst, "non-finite value %s: object velocity obj_vel[%d] (%s) is not finite", when,
                  which + 1, rates[which % 3]);
        break;
    case HH_ERR_TAU:
        LOG_ERROR(inst, "non-finite input %s: tau[%d] (%s joint %d)", when, which + 1, finger, which % 3 + 1);
        break;
    case HH_ERR_F_EXT:
        LOG_ERROR(inst, "non-finite input %s: f_ext[%d]", when, which + 1);
        break;
    default:
        LOG_ERROR(inst, "the plant failed %s (code %d)", when, code);
    }
}

/* Pack the current parameters, make the initial state and its outputs; 0 or -1 (logged). */
static int build_model(hh_instance *inst)
{
    if (inst->model_current)
        return 0;
    release_model(inst);
    if (hh_model_from_hand(&inst->model, inst->hand, inst->dt, report_parameter, inst) != 0)
        return -1;
    if (hh_work_init(&inst->work, inst->model.npts) != 0) {
        LOG_ERROR(inst, "out of memory for %d surface points", inst->model.npts);
        return -1;
    }
    inst->state_size = hh_state_size(&inst->model);
    inst->state = malloc(inst->state_size * sizeof(double));
    if (inst->state == NULL) {
        LOG_ERROR(inst, "out of memory for a state of %zu values", inst->state_size);
        release_model(inst);
        return -1;
    }
    hh_initial_state(&inst->model, inst->state);
    int which;
    int code = hh_output(&inst->model, &inst->work, inst->state, inst->outputs, &which);
    if (code != HH_OK) {
        describe_failure(inst, code, which, inst->start_time, 0);
        release_model(inst);
        return -1;
    }
    inst->steps = 0;
    inst->model_current = 1;
    return 0;
}

static hh_status wrong_phase(hh_instance *inst, const char *what)
{
    LOG_ERROR(inst, "%s is not allowed when the instance is %s", what, PHASE_NAMES[inst->phase]);
    return HH_STATUS_ERROR;
}

hh_status hh_instance_enter_initialization(hh_instance *inst, double start_time)
{
    if (inst->phase != HH_INSTANTIATED)
        return wrong_phase(inst, "entering initialization mode");
    if (!isfinite(start_time)) {
        LOG_ERROR(inst, "the start time must be finite, got %g", start_time);
        return HH_STATUS_ERROR;
    }
    inst->start_time = start_time;
    inst->model_current = 0;
    inst->phase = HH_INITIALIZATION;
    return HH_STATUS_OK;
}

hh_status hh_instance_exit_initialization(hh_instance *inst)
{
    if (inst->phase != HH_INITIALIZATION)
        return wrong_phase(inst, "exiting initialization mode");
    if (build_model(inst) != 0) {
        inst->phase = HH_FAILED;
        return HH_STATUS_ERROR;
    }
    inst->phase = HH_STEPPING;
    LOG_EVENT(inst, "initialized: %d surface points, state of %zu values", inst->model.npts, inst->state_size);
    return HH_STATUS_OK;
}

double hh_instance_time(const hh_instance *inst)
{
    return inst->start_time + (double)inst->steps * inst->dt;
}

hh_status hh_instance_terminate(hh_instance *inst)
{
    if (inst->phase != HH_STEPPING && inst->phase != HH_FAILED && inst->phase != HH_INITIALIZATION)
        return wrong_phase(inst, "terminate");
    inst->phase = HH_TERMINATED;
    return HH_STATUS_OK;
}

hh_status hh_instance_reset(hh_instance *inst)
{
    release_model(inst);
    memcpy(inst->hand, inst->defaults, sizeof inst->hand);
    memset(inst->inputs, 0, sizeof inst->inputs);
    memset(inst->outputs, 0, sizeof inst->outputs);
    inst->start_time = 0.0;
    inst->steps = 0;
    inst->phase = HH_INSTANTIATED;
    return HH_STATUS_OK;
}

/* -- variables -------------------------------------------------------------------------------- */

static int is_param(unsigned int vr)
{
    return vr >= HH_VR_PARAM && vr < HH_VR_PARAM + HH_HAND_PARAMS;
}

static int is_input(unsigned int vr)
{
    return vr >= HH_VR_TAU && vr < HH_VR_TAU + HH_N_INPUTS;
}

static int is_output(unsigned int vr)
{
    return vr >= HH_VR_OUTPUT && vr < HH_VR_OUTPUT + HH_N_OUTPUTS;
}

hh_status hh_instance_get(hh_instance *inst, const unsigned int *vr, size_t n, double *values)
{
    if (inst->phase == HH_FAILED)
        return wrong_phase(inst, "getting values");
    for (size_t i = 0; i < n; i++) {
        unsigned int r = vr[i];
        if (is_output(r) && inst->phase == HH_INSTANTIATED) {
            LOG_ERROR(inst, "output %u is calculated from the parameters: read it after entering initialization mode",
                      r);
            return HH_STATUS_ERROR;
        }
        if (is_output(r) && !inst->model_current && build_model(inst) != 0)
            return HH_STATUS_ERROR;
    }
    for (size_t i = 0; i < n; i++) {
        unsigned int r = vr[i];
        if (r == HH_VR_TIME)
            values[i] = hh_instance_time(inst);
        else if (is_input(r))
            values[i] = inst->inputs[r - HH_VR_TAU];
        else if (is_output(r))
            values[i] = inst->outputs[r - HH_VR_OUTPUT];
        else if (is_param(r))
            values[i] = inst->hand[r - HH_VR_PARAM];
        else {
            LOG_ERROR(inst, "unknown value reference %u", r);
            return HH_STATUS_ERROR;
        }
    }
    return HH_STATUS_OK;
}

hh_status hh_instance_set(hh_instance *inst, const unsigned int *vr, size_t n, const double *values)
{
    if (inst->phase == HH_FAILED || inst->phase == HH_TERMINATED)
        return wrong_phase(inst, "setting values");
    for (size_t i = 0; i < n; i++) {
        unsigned int r = vr[i];
        if (is_input(r)) {
            inst->inputs[r - HH_VR_TAU] = values[i];
        } else if (is_param(r)) {
            if (inst->phase != HH_INSTANTIATED && inst->phase != HH_INITIALIZATION) {
                LOG_ERROR(inst, "parameter %s can only be set before initialization ends (variability fixed)",
                          hh_hand_param_name((int)(r - HH_VR_PARAM)));
                return HH_STATUS_ERROR;
            }
            inst->hand[r - HH_VR_PARAM] = values[i];
            inst->model_current = 0;
        } else if (is_output(r) || r == HH_VR_TIME) {
            LOG_ERROR(inst, "value reference %u is not an input or a parameter: it cannot be set", r);
            return HH_STATUS_ERROR;
        } else {
            LOG_ERROR(inst, "unknown value reference %u", r);
            return HH_STATUS_ERROR;
        }
    }
    return HH_STATUS_OK;
}

/* -- stepping --------------------------------------------------------------------------------- */

hh_status hh_instance_do_step(hh_instance *inst, double current_time, double step)
{
    (void)current_time; /* time is counted in internal steps, so it never drifts */
    if (inst->phase != HH_STEPPING)
        return wrong_phase(inst, "a step");
    double count = step / inst->dt;
    double whole = nearbyint(count);
    if (!(step >= 0.0) || !(whole <= MAX_STEPS_PER_CALL) || fabs(count - whole) > STEP_TOLERANCE) {
        LOG_ERROR(inst,
                  "communication step %.10g s is not a whole multiple of the internal step %g s (hint: use "
                  "multiples of %g s)",
                  step, inst->dt, inst->dt);
        return HH_STATUS_ERROR;
    }
    long n = (long)whole;
    if (n == 0)
        return HH_STATUS_OK;
    long done;
    int which;
    int code = hh_advance(&inst->model, &inst->work, inst->state, inst->inputs, inst->inputs + 9, n, inst->outputs, 0,
                          &done, &which);
    if (code != HH_OK) {
        /* step 'done' is the one that failed: it started 'done - 1' steps in */
        describe_failure(inst, code, which, hh_instance_time(inst) + (double)(done > 0 ? done - 1 : 0) * inst->dt, 1);
        inst->phase = HH_FAILED;
        return HH_STATUS_ERROR;
    }
    inst->steps += n;
    return HH_STATUS_OK;
}

/* -- FMU states ------------------------------------------------------------------------------- */

#define SNAPSHOT_MAGIC "HHFMUST1"

struct hh_snapshot {
    char magic[8];
    double hand[HH_HAND_PARAMS];
    double inputs[HH_N_INPUTS];
    double outputs[HH_N_OUTPUTS];
    double start_time;
    long long steps;
    int phase;
    int model_current;
    size_t state_size;
    double state[]; /* state_size values when model_current */
};

static hh_status missing_argument(hh_instance *inst, const char *what)
{
    LOG_ERROR(inst, "%s is NULL", what);
    return HH_STATUS_ERROR;
}

hh_status hh_instance_get_state(hh_instance *inst, hh_snapshot **snapshot)
{
    if (snapshot == NULL)
        return missing_argument(inst, "the pointer for the FMU state");
    size_t values = inst->model_current ? inst->state_size : 0;
    hh_snapshot *s = *snapshot;
    if (s == NULL || s->state_size != values) {
        hh_snapshot_free(snapshot);
        s = malloc(sizeof *s + values * sizeof(double));
        if (s == NULL) {
            LOG_ERROR(inst, "out of memory for an FMU state");
            return HH_STATUS_ERROR;
        }
    }
    memset(s, 0, sizeof *s);
    memcpy(s->magic, SNAPSHOT_MAGIC, 8);
    memcpy(s->hand, inst->hand, sizeof s->hand);
    memcpy(s->inputs, inst->inputs, sizeof s->inputs);
    memcpy(s->outputs, inst->outputs, sizeof s->outputs);
    s->start_time = inst->start_time;
    s->steps = inst->steps;
    s->phase = (int)inst->phase;
    s->model_current = inst->model_current;
    s->state_size = values;
    if (values > 0)
        memcpy(s->state, inst->state, values * sizeof(double));
    *snapshot = s;
    return HH_STATUS_OK;
}

hh_status hh_instance_set_state(hh_instance *inst, const hh_snapshot *s)
{
    if (s == NULL || memcmp(s->magic, SNAPSHOT_MAGIC, 8) != 0) {
        LOG_ERROR(inst, "not an FMU state of this FMU");
        return HH_STATUS_ERROR;
    }
    release_model(inst);
    memcpy(inst->hand, s->hand, sizeof inst->hand);
    inst->start_time = s->start_time;
    if (s->model_current) {
        hh_phase phase = inst->phase;
        if (build_model(inst) != 0 || inst->state_size != s->state_size) {
            if (inst->model_current)
                LOG_ERROR(inst, "the FMU state holds %zu state values, its parameters give %zu", s->state_size,
                          inst->state_size);
            release_model(inst);
            inst->phase = HH_FAILED;
            return HH_STATUS_ERROR;
        }
        inst->phase = phase;
        memcpy(inst->state, s->state, s->state_size * sizeof(double));
    }
    memcpy(inst->inputs, s->inputs, sizeof inst->inputs);
    memcpy(inst->outputs, s->outputs, sizeof inst->outputs);
    inst->steps = s->steps;
    inst->phase = (hh_phase)s->phase;
    return HH_STATUS_OK;
}

hh_status hh_snapshot_free(hh_snapshot **snapshot)
{
    if (snapshot != NULL) {
        free(*snapshot);
        *snapshot = NULL;
    }
    return HH_STATUS_OK;
}

static size_t snapshot_bytes(const hh_snapshot *snapshot)
{
    return sizeof *snapshot + snapshot->state_size * sizeof(double);
}

hh_status hh_snapshot_size(hh_instance *inst, const hh_snapshot *snapshot, size_t *size)
{
    if (snapshot == NULL || size == NULL)
        return missing_argument(inst, snapshot == NULL ? "the FMU state" : "the pointer for its size");
    *size = snapshot_bytes(snapshot);
    return HH_STATUS_OK;
}

hh_status hh_snapshot_serialize(hh_instance *inst, const hh_snapshot *snapshot, unsigned char *bytes, size_t size)
{
    if (snapshot == NULL || bytes == NULL)
        return missing_argument(inst, snapshot == NULL ? "the FMU state" : "the buffer for the serialized state");
    size_t need = snapshot_bytes(snapshot);
    if (size < need) {
        LOG_ERROR(inst, "the buffer for the serialized FMU state holds %zu bytes, it needs %zu", size, need);
        return HH_STATUS_ERROR;
    }
    memcpy(bytes, snapshot, need);
    return HH_STATUS_OK;
}

hh_status hh_snapshot_deserialize(hh_instance *inst, const unsigned char *bytes, size_t size, hh_snapshot **snapshot)
{
    if (bytes == NULL || snapshot == NULL)
        return missing_argument(inst, bytes == NULL ? "the serialized state" : "the pointer for the FMU state");
    hh_snapshot head;
    if (size < sizeof head) {
        LOG_ERROR(inst, "a serialized FMU state of %zu bytes is too short", size);
        return HH_STATUS_ERROR;
    }
    memcpy(&head, bytes, sizeof head);
    if (memcmp(head.magic, SNAPSHOT_MAGIC, 8) != 0 || head.state_size > (size - sizeof head) / sizeof(double) ||
        size != sizeof head + head.state_size * sizeof(double) || head.phase < HH_INSTANTIATED ||
        head.phase > HH_FAILED) {
        LOG_ERROR(inst, "the bytes are not a serialized FMU state of this FMU");
        return HH_STATUS_ERROR;
    }
    hh_snapshot *s = malloc(size);
    if (s == NULL) {
        LOG_ERROR(inst, "out of memory for an FMU state");
        return HH_STATUS_ERROR;
    }
    memcpy(s, bytes, size);
    hh_snapshot_free(snapshot);
    *snapshot = s;
    return HH_STATUS_OK;
}
