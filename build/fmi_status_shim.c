/*
 * fmi_status_shim.c - FMI 2.0 Co-Simulation front end for the Python-backed FMUs.
 *
 * The Python slaves never raise: on bad input they log a message with status
 * fmi2Error (or fmi2Warning/fmi2Discard) and return normally, keeping their
 * last good state.  The library that runs them reports such a call as fmi2OK,
 * and it passes log messages on only while debug logging is on.
 *
 * This library is installed as binaries/linux64/<modelIdentifier>.so; the
 * library that runs the Python slave sits next to it as
 * <modelIdentifier>_pythonfmu.so ("inner library").  Every FMI call is
 * forwarded to the inner library, and:
 *   - the inner library's debug logging is always on, so every message passes
 *     through here; warnings, errors and fatal errors always reach the host's
 *     logger, fmi2OK and fmi2Discard messages only while the host has debug
 *     logging on (restricted to the categories it asked for, if any);
 *   - a call returns the worse of the inner library's status and the worst
 *     status logged during the call.  A logged fmi2Fatal counts as fmi2Error:
 *     the slave returned normally, so the instance is still usable.  A status
 *     returned by the inner library (fmi2Fatal from an exception included)
 *     passes through unchanged.
 *
 * A call on one instance touches only that instance's record, so instances
 * may be used from different threads (each by one thread at a time, as FMI
 * requires).
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "python_runtime.h"

/* ---- FMI 2.0 types (platform "default") -------------------------------- */

typedef void*              fmi2Component;
typedef void*              fmi2ComponentEnvironment;
typedef void*              fmi2FMUstate;
typedef unsigned int       fmi2ValueReference;
typedef double             fmi2Real;
typedef int                fmi2Integer;
typedef int                fmi2Boolean;
typedef char               fmi2Char;
typedef const fmi2Char*    fmi2String;
typedef char               fmi2Byte;

#define fmi2True  1
#define fmi2False 0

typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime, fmi2Terminated } fmi2StatusKind;

typedef void  (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String instanceName, fmi2Status,
                                    fmi2String category, fmi2String message, ...);
typedef void* (*fmi2CallbackAllocateMemory)(size_t, size_t);
typedef void  (*fmi2CallbackFreeMemory)(void*);
typedef void  (*fmi2StepFinished)(fmi2ComponentEnvironment, fmi2Status);

typedef struct {
    fmi2CallbackLogger         logger;
    fmi2CallbackAllocateMemory allocateMemory;
    fmi2CallbackFreeMemory     freeMemory;
    fmi2StepFinished           stepFinished;
    fmi2ComponentEnvironment   componentEnvironment;
} fmi2CallbackFunctions;

/* ---- the exported API --------------------------------------------------- */

#define EXPORT __attribute__((visibility("default")))

EXPORT const char* fmi2GetTypesPlatform(void);
EXPORT const char* fmi2GetVersion(void);
EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component, fmi2Boolean, size_t, const fmi2String[]);
EXPORT fmi2Component fmi2Instantiate(fmi2String, fmi2Type, fmi2String, fmi2String,
                                     const fmi2CallbackFunctions*, fmi2Boolean, fmi2Boolean);
EXPORT void fmi2FreeInstance(fmi2Component);
EXPORT fmi2Status fmi2SetupExperiment(fmi2Component, fmi2Boolean, fmi2Real, fmi2Real, fmi2Boolean, fmi2Real);
EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component);
EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component);
EXPORT fmi2Status fmi2Terminate(fmi2Component);
EXPORT fmi2Status fmi2Reset(fmi2Component);
EXPORT fmi2Status fmi2GetReal(fmi2Component, const fmi2ValueReference[], size_t, fmi2Real[]);
EXPORT fmi2Status fmi2GetInteger(fmi2Component, const fmi2ValueReference[], size_t, fmi2Integer[]);
EXPORT fmi2Status fmi2GetBoolean(fmi2Component, const fmi2ValueReference[], size_t, fmi2Boolean[]);
EXPORT fmi2Status fmi2GetString(fmi2Component, const fmi2ValueReference[], size_t, fmi2String[]);
EXPORT fmi2Status fmi2SetReal(fmi2Component, const fmi2ValueReference[], size_t, const fmi2Real[]);
EXPORT fmi2Status fmi2SetInteger(fmi2Component, const fmi2ValueReference[], size_t, const fmi2Integer[]);
EXPORT fmi2Status fmi2SetBoolean(fmi2Component, const fmi2ValueReference[], size_t, const fmi2Boolean[]);
EXPORT fmi2Status fmi2SetString(fmi2Component, const fmi2ValueReference[], size_t, const fmi2String[]);
EXPORT fmi2Status fmi2GetFMUstate(fmi2Component, fmi2FMUstate*);
EXPORT fmi2Status fmi2SetFMUstate(fmi2Component, fmi2FMUstate);
EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component, fmi2FMUstate*);
EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component, fmi2FMUstate, size_t*);
EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component, fmi2FMUstate, fmi2Byte[], size_t);
EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component, const fmi2Byte[], size_t, fmi2FMUstate*);
EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component, const fmi2ValueReference[], size_t,
                                               const fmi2ValueReference[], size_t, const fmi2Real[], fmi2Real[]);
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component, const fmi2ValueReference[], size_t,
                                              const fmi2Integer[], const fmi2Real[]);
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component, const fmi2ValueReference[], size_t,
                                               const fmi2Integer[], fmi2Real[]);
EXPORT fmi2Status fmi2DoStep(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean);
EXPORT fmi2Status fmi2CancelStep(fmi2Component);
EXPORT fmi2Status fmi2GetStatus(fmi2Component, const fmi2StatusKind, fmi2Status*);
EXPORT fmi2Status fmi2GetRealStatus(fmi2Component, const fmi2StatusKind, fmi2Real*);
EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component, const fmi2StatusKind, fmi2Integer*);
EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component, const fmi2StatusKind, fmi2Boolean*);
EXPORT fmi2Status fmi2GetStringStatus(fmi2Component, const fmi2StatusKind, fmi2String*);

/* Functions taken from the inner library (the two version queries are
 * answered here: they are fixed by the API this file implements). */
#define INNER_FUNCTIONS(X)                                                        \
    X(fmi2SetDebugLogging) X(fmi2Instantiate) X(fmi2FreeInstance)                 \
    X(fmi2SetupExperiment) X(fmi2EnterInitializationMode)                         \
    X(fmi2ExitInitializationMode) X(fmi2Terminate) X(fmi2Reset)                   \
    X(fmi2GetReal) X(fmi2GetInteger) X(fmi2GetBoolean) X(fmi2GetString)           \
    X(fmi2SetReal) X(fmi2SetInteger) X(fmi2SetBoolean) X(fmi2SetString)           \
    X(fmi2GetFMUstate) X(fmi2SetFMUstate) X(fmi2FreeFMUstate)                     \
    X(fmi2SerializedFMUstateSize) X(fmi2SerializeFMUstate)                        \
    X(fmi2DeSerializeFMUstate) X(fmi2GetDirectionalDerivative)                    \
    X(fmi2SetRealInputDerivatives) X(fmi2GetRealOutputDerivatives)                \
    X(fmi2DoStep) X(fmi2CancelStep) X(fmi2GetStatus) X(fmi2GetRealStatus)         \
    X(fmi2GetIntegerStatus) X(fmi2GetBooleanStatus) X(fmi2GetStringStatus)

/* Same signatures as ours, so the compiler checks every forwarded call. */
#define DECLARE_POINTER(name) __typeof__(name)* name;
static struct {
    void* handle;
    INNER_FUNCTIONS(DECLARE_POINTER)
} inner;

#define INNER_SUFFIX "_pythonfmu.so"

static char inner_path[PATH_MAX];   /* set when this library is loaded */
static char load_error[6 * PATH_MAX];
static pthread_once_t load_once = PTHREAD_ONCE_INIT;

static void read_variables(const char* root);

/* Locate the inner library while the host's working directory is still the
 * one this library was loaded from (dladdr may report a relative name). */
__attribute__((constructor)) static void find_inner_library(void)
{
    Dl_info self;
    char own[PATH_MAX];
    if (!dladdr(inner_path, &self) || self.dli_fname == NULL) return;
    if (realpath(self.dli_fname, own) == NULL) snprintf(own, sizeof own, "%s", self.dli_fname);
    size_t n = strlen(own);
    if (n > 3 && strcmp(own + n - 3, ".so") == 0) own[n - 3] = '\0';
    snprintf(inner_path, sizeof inner_path, "%s%s", own, INNER_SUFFIX);
}

static void (*release_guard)(void);

static void release_inner_guard(void)
{
    if (release_guard != NULL) release_guard();
}

static void load_inner_library(void)
{
    if (inner_path[0] == '\0') {
        snprintf(load_error, sizeof load_error, "cannot determine the path of the FMU's binary");
        return;
    }
    /* The inner library needs a Python in the process: find and start one first
     * (python_runtime.c).  Its top folder is three levels above: binaries/linux64/. */
    char root[PATH_MAX];
    snprintf(root, sizeof root, "%s", inner_path);
    for (int level = 0; level < 3; level++) {
        char* slash = strrchr(root, '/');
        if (slash != NULL) *slash = '\0';
    }
    if (!python_runtime_ready(root, load_error, sizeof load_error)) return;
    read_variables(root);
    void* handle = dlopen(inner_path, RTLD_NOW | RTLD_LOCAL);
    if (handle == NULL) {
        snprintf(load_error, sizeof load_error, "cannot load %s: %s", inner_path, dlerror());
        return;
    }
#define LOAD_POINTER(name)                                                        \
    if ((inner.name = (__typeof__(inner.name))dlsym(handle, #name)) == NULL) {   \
        snprintf(load_error, sizeof load_error, "%s lacks %s", inner_path, #name); \
        dlclose(handle);                                                          \
        memset(&inner, 0, sizeof inner);                                          \
        return;                                                                   \
    }
    INNER_FUNCTIONS(LOAD_POINTER)
    inner.handle = handle;
    /* pythonfmu 0.7.0 keeps its interpreter guard in a static shared_ptr that both
     * its static destructor and its unload hook release: at exit (or unload) it is
     * released twice and the heap is corrupted, which later aborts the host
     * ("free(): corrupted unsorted chunks").  Releasing it once, through the hook's
     * own exported function, before either runs makes the two later releases no-ops.
     * Handlers registered after the inner library was loaded run before its static
     * destructors. */
    release_guard = (void (*)(void))dlsym(handle, "finalizePythonInterpreter");
    if (release_guard != NULL) atexit(release_inner_guard);
}

/* ---- the model's variables ------------------------------------------------ */

/* Value references, types and settability from modelDescription.xml.  A get or
 * set naming a variable that is not there, or of another type, or setting an
 * output, makes the Python slave raise, which pythonfmu answers with fmi2Fatal
 * and an unusable instance; such calls are refused here with fmi2Error.  An
 * unreadable description leaves the table empty and the checks off. */
typedef struct {
    fmi2ValueReference vr;
    char type;      /* 'r' Real, 'i' Integer or Enumeration, 'b' Boolean, 's' String */
    char settable;  /* causality parameter or input */
} Variable;

static Variable* variables;
static size_t n_variables;

static void read_variables(const char* root)
{
    char path[PATH_MAX + 32];
    snprintf(path, sizeof path, "%s/modelDescription.xml", root);
    FILE* file = fopen(path, "rb");
    if (file == NULL) return;
    fseek(file, 0, SEEK_END);
    long size = ftell(file);
    fseek(file, 0, SEEK_SET);
    char* text = size > 0 ? malloc((size_t)size + 1) : NULL;
    if (text == NULL || fread(text, 1, (size_t)size, file) != (size_t)size) {
        free(text);
        fclose(file);
        return;
    }
    fclose(file);
    text[size] = '\0';
    size_t capacity = 0, n = 0;
    Variable* table = NULL;
    for (char* p = strstr(text, "<ScalarVariable"); p != NULL; p = strstr(p + 1, "<ScalarVariable")) {
        char* end = strchr(p, '>');
        if (end == NULL) break;
        *end = '\0';
        char* ref = strstr(p, " valueReference=\"");
        char* causality = strstr(p, " causality=\"");
        Variable v = {0, 0, 0};
        if (ref != NULL) v.vr = (fmi2ValueReference)strtoul(ref + 17, NULL, 10);
        v.settable = causality != NULL && (strncmp(causality + 12, "parameter\"", 10) == 0 ||
                                           strncmp(causality + 12, "input\"", 6) == 0);
        *end = '>';
        char* child = end + 1;
        while (*child == ' ' || *child == '\n' || *child == '\r' || *child == '\t') child++;
        if (strncmp(child, "<Real", 5) == 0) v.type = 'r';
        else if (strncmp(child, "<Integer", 8) == 0 || strncmp(child, "<Enumeration", 12) == 0) v.type = 'i';
        else if (strncmp(child, "<Boolean", 8) == 0) v.type = 'b';
        else if (strncmp(child, "<String", 7) == 0) v.type = 's';
        if (ref == NULL || v.type == 0) continue;
        if (n == capacity) {
            capacity = capacity ? 2 * capacity : 64;
            Variable* grown = realloc(table, capacity * sizeof *table);
            if (grown == NULL) { free(table); free(text); return; }
            table = grown;
        }
        table[n++] = v;
    }
    free(text);
    variables = table;
    n_variables = n;
}

/* The inner library lives exactly as long as this one. */
__attribute__((destructor)) static void unload_inner_library(void)
{
    release_inner_guard();
    if (inner.handle != NULL) dlclose(inner.handle);
}

/* ---- instances ----------------------------------------------------------- */

typedef struct {
    fmi2Component         component;   /* the inner library's instance */
    char*                 name;        /* instanceName, for messages from here */
    char*                 resources;   /* fmuResourceLocation, to find the slave again after a reset */
    int                   dead;        /* the inner instance answered fmi2Fatal */
    fmi2CallbackFunctions host;        /* the caller's callbacks, as given */
    fmi2CallbackFunctions given;       /* what the inner library gets; it keeps the pointer */
    fmi2Status            logged;      /* worst status logged during the current call */
    fmi2Boolean           debugLogging;
    size_t                nCategories; /* 0: all categories */
    char**                categories;
    PythonSlave           slave;       /* its Python slave, whose do_step fmi2DoStep calls directly */
    int                   stepped;     /* the last step taken went the direct way: lastSuccessfulTime is ours */
    fmi2Real              lastSuccessfulTime;
} Instance;

static void forget_categories(Instance* inst)
{
    for (size_t i = 0; i < inst->nCategories; i++) free(inst->categories[i]);
    free(inst->categories);
    inst->categories = NULL;
    inst->nCategories = 0;
}

/* FMI 2.0 (2.1.3): messages behind fmi2Warning, fmi2Error and fmi2Fatal are
 * shown to the user; fmi2OK and fmi2Discard messages only in debug mode. */
static int host_wants(const Instance* inst, fmi2Status status, fmi2String category)
{
    if (status != fmi2OK && status != fmi2Discard) return 1;
    if (!inst->debugLogging) return 0;
    if (inst->nCategories == 0) return 1;
    for (size_t i = 0; i < inst->nCategories; i++)
        if (category != NULL && strcmp(category, inst->categories[i]) == 0) return 1;
    return 0;
}

static void shim_logger(fmi2ComponentEnvironment env, fmi2String instanceName, fmi2Status status,
                        fmi2String category, fmi2String message, ...)
{
    Instance* inst = (Instance*)env;

    /* A logged problem is what the call returns; a slave that logged and
     * returned normally is still usable, so that is never fmi2Fatal. */
    fmi2Status as_returned = status > fmi2Error ? fmi2Error : status;
    if (status <= fmi2Fatal && as_returned > inst->logged) inst->logged = as_returned;

    if (inst->host.logger == NULL || !host_wants(inst, status, category)) return;

    /* The message is passed on as plain text, not formatted: pythonfmu hands
     * over the slave's text as the format and never supplies arguments, so
     * formatting would read arguments that do not exist as soon as the text
     * contains '%' (a crash for "%s").  Through "%s" the host formats nothing
     * either. */
    inst->host.logger(inst->host.componentEnvironment, instanceName, status, category, "%s",
                      message != NULL ? message : "");
}

/* stepFinished gets the environment the host gave, not our record. */
static void shim_step_finished(fmi2ComponentEnvironment env, fmi2Status status)
{
    Instance* inst = (Instance*)env;
    inst->host.stepFinished(inst->host.componentEnvironment, status);
}

/* A message from the front end itself (never printf-formatted by the host). */
static void shim_log(Instance* inst, fmi2Status status, const char* format, ...)
{
    if (status > inst->logged && status <= fmi2Fatal) inst->logged = status > fmi2Error ? fmi2Error : status;
    if (inst->host.logger == NULL) return;
    char message[1024];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    inst->host.logger(inst->host.componentEnvironment, inst->name, status,
                      status == fmi2Error ? "logStatusError" : "logStatusFatal", "%s", message);
}

/* After fmi2Fatal pythonfmu has released the slave: any further call would touch freed memory. */
static fmi2Status refuse_dead(Instance* inst, const char* function)
{
    shim_log(inst, fmi2Error, "%s: this instance failed fatally earlier (see the previous message) and can "
             "only be freed; instantiate a new one", function);
    return fmi2Error;
}

static const char* type_name(char type)
{
    switch (type) {
    case 'r': return "Real";
    case 'i': return "Integer";
    case 'b': return "Boolean";
    default: return "String";
    }
}

/* Every value reference names a variable of the function's type (and, to set, a
 * parameter or input); otherwise log and refuse the whole call. */
static int references_fit(Instance* inst, const char* function, const fmi2ValueReference vr[], size_t nvr,
                          const void* values, char type, int set)
{
    if (nvr > 0 && (vr == NULL || values == NULL)) {
        shim_log(inst, fmi2Error, "%s: %zu values asked for with a NULL array", function, nvr);
        return 0;
    }
    if (n_variables == 0) return 1;
    for (size_t i = 0; i < nvr; i++) {
        const Variable* found = NULL;
        for (size_t k = 0; k < n_variables && found == NULL; k++)
            if (variables[k].vr == vr[i] && variables[k].type == type) found = &variables[k];
        if (found == NULL) {
            shim_log(inst, fmi2Error, "%s: value reference %u is not a %s variable of this FMU; nothing was %s",
                     function, vr[i], type_name(type), set ? "set" : "read");
            return 0;
        }
        if (set && !found->settable) {
            shim_log(inst, fmi2Error, "%s: value reference %u is an output or local variable and cannot be set; "
                     "nothing was set", function, vr[i]);
            return 0;
        }
    }
    return 1;
}

static fmi2Status worse(fmi2Status returned, fmi2Status logged)
{
    if (returned > fmi2Fatal) return returned;  /* fmi2Pending is no severity */
    return logged > returned ? logged : returned;
}

/* ---- functions without an instance ------------------------------------ */

const char* fmi2GetTypesPlatform(void) { return "default"; }
const char* fmi2GetVersion(void) { return "2.0"; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions* functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    pthread_once(&load_once, load_inner_library);
    if (inner.handle == NULL) {
        if (functions != NULL && functions->logger != NULL)
            functions->logger(functions->componentEnvironment, instanceName, fmi2Fatal, "logStatusFatal",
                              "%s", load_error);
        return NULL;
    }

    Instance* inst = calloc(1, sizeof *inst);
    if (inst == NULL) return NULL;
    if (functions != NULL) inst->host = *functions;
    inst->debugLogging = loggingOn;
    inst->given = inst->host;
    inst->given.logger = shim_logger;
    inst->given.stepFinished = inst->host.stepFinished != NULL ? shim_step_finished : NULL;
    inst->given.componentEnvironment = inst;
    inst->name = strdup(instanceName != NULL ? instanceName : "");
    inst->resources = strdup(fmuResourceLocation != NULL ? fmuResourceLocation : "");

    /* Debug logging on inside: messages of every status must pass through
     * shim_logger for the status to be seen at all. */
    inst->component = inner.fmi2Instantiate(instanceName, fmuType, fmuGUID, fmuResourceLocation,
                                            &inst->given, visible, fmi2True);
    if (inst->component == NULL) {
        free(inst->name);
        free(inst->resources);
        free(inst);
        return NULL;
    }
    python_slave_claim(&inst->slave, instanceName, fmuResourceLocation);
    return inst;
}

void fmi2FreeInstance(fmi2Component c)
{
    Instance* inst = (Instance*)c;
    if (inst == NULL) return;
    /* pythonfmu 0.7.0 forwards the messages still queued when an instance is
     * destroyed, and with debug logging on that crashes the host (seen when an
     * instance is freed right after fmi2Instantiate).  Nothing logged while
     * freeing is of use to the host, so logging goes off first. */
    python_slave_release(&inst->slave);
    if (!inst->dead) {
        inner.fmi2SetDebugLogging(inst->component, fmi2False, 0, NULL);
        inner.fmi2FreeInstance(inst->component);
    }
    /* else pythonfmu has released the slave's objects already, and freeing its
     * instance would release them again: the small remainder is left alone. */
    forget_categories(inst);
    free(inst->name);
    free(inst->resources);
    free(inst);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    Instance* inst = (Instance*)c;
    if (inst == NULL || (nCategories > 0 && categories == NULL)) return fmi2Error;
    inst->logged = fmi2OK;
    if (inst->dead) return refuse_dead(inst, "fmi2SetDebugLogging");
    char** copy = nCategories > 0 ? calloc(nCategories, sizeof *copy) : NULL;
    if (nCategories > 0 && copy == NULL) return fmi2Error;
    for (size_t i = 0; i < nCategories; i++) {
        copy[i] = strdup(categories[i] != NULL ? categories[i] : "");
        if (copy[i] == NULL) {
            for (size_t j = 0; j < i; j++) free(copy[j]);
            free(copy);
            return fmi2Error;
        }
    }
    forget_categories(inst);
    inst->debugLogging = loggingOn;
    inst->nCategories = nCategories;
    inst->categories = copy;

    inst->logged = fmi2OK;
    return worse(inner.fmi2SetDebugLogging(inst->component, fmi2True, 0, NULL), inst->logged);
}

/* ---- forwarded instance functions -------------------------------------- */

/* Define `name` with parameter list `params`; the remaining arguments are
 * the inner call's arguments, written with `inst->component` for the instance. */
#define FORWARD(name, params, ...) FORWARD_IF(name, params, 1, __VA_ARGS__)

/* The same, forwarding only if `admissible` holds (it logs why not). */
#define FORWARD_IF(name, params, admissible, ...)                                 \
    fmi2Status name params                                                        \
    {                                                                             \
        Instance* inst = (Instance*)c;                                            \
        if (inst == NULL) return fmi2Error;                                       \
        inst->logged = fmi2OK;                                                    \
        if (inst->dead) return refuse_dead(inst, #name);                          \
        if (!(admissible)) return fmi2Error;                                      \
        fmi2Status returned = inner.name(__VA_ARGS__);                            \
        if (returned == fmi2Fatal) inst->dead = 1;                                \
        return worse(returned, inst->logged);                                     \
    }

/* Get and set: value references checked against the model description. */
#define FORWARD_VALUES(name, type, set, params)                                   \
    FORWARD_IF(name, params, references_fit(inst, #name, vr, nvr, value, type, set), \
               inst->component, vr, nvr, value)

FORWARD(fmi2SetupExperiment,
        (fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance, fmi2Real startTime,
         fmi2Boolean stopTimeDefined, fmi2Real stopTime),
        inst->component, toleranceDefined, tolerance, startTime, stopTimeDefined, stopTime)
FORWARD(fmi2EnterInitializationMode, (fmi2Component c), inst->component)
FORWARD(fmi2ExitInitializationMode, (fmi2Component c), inst->component)
FORWARD(fmi2Terminate, (fmi2Component c), inst->component)

/* pythonfmu makes a new Python slave on reset: the direct doStep follows it. */
fmi2Status fmi2Reset(fmi2Component c)
{
    Instance* inst = (Instance*)c;
    if (inst == NULL) return fmi2Error;
    inst->logged = fmi2OK;
    if (inst->dead) return refuse_dead(inst, "fmi2Reset");
    python_slave_release(&inst->slave);
    fmi2Status returned = inner.fmi2Reset(inst->component);
    if (returned == fmi2Fatal) inst->dead = 1;
    else python_slave_claim(&inst->slave, inst->name, inst->resources);
    return worse(returned, inst->logged);
}

/* Outputs read after a doStep come from the Block's observation without Python where
 * they can (python_slave_native_get: the same bits as the slave's read); any other read
 * goes to pythonfmu.  The references' types are checked first, against the model
 * description: the record's one table holds the outputs of every type.  An Integer
 * beyond fmi2Integer's range is left to the slave, which reports it. */
#define NATIVE_READS_AT_ONCE 64
#define AS_REAL(x) (x)
#define AS_INTEGER(x) ((fmi2Integer)(x))
#define AS_BOOLEAN(x) ((x) != 0.0 ? fmi2True : fmi2False)
#define FITS_ANY(x) 1
#define FITS_INTEGER(x) (fabs(x) < 2147483648.0)
#define GET_OUTPUTS(name, type, ctype, convert, fits)                                            \
    fmi2Status name(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, ctype value[])   \
    {                                                                                            \
        Instance* inst = (Instance*)c;                                                           \
        if (inst == NULL) return fmi2Error;                                                      \
        inst->logged = fmi2OK;                                                                   \
        if (inst->dead) return refuse_dead(inst, #name);                                         \
        if (!references_fit(inst, #name, vr, nvr, value, type, 0)) return fmi2Error;             \
        double read[NATIVE_READS_AT_ONCE];                                                       \
        if (n_variables > 0 && nvr > 0 && nvr <= NATIVE_READS_AT_ONCE &&                         \
            python_slave_native_get(&inst->slave, vr, nvr, read)) {                              \
            size_t fitting = 0;                                                                  \
            while (fitting < nvr && fits(read[fitting])) fitting++;                              \
            if (fitting == nvr) {                                                                \
                for (size_t i = 0; i < nvr; i++) value[i] = convert(read[i]);                    \
                return fmi2OK;                                                                   \
            }                                                                                    \
        }                                                                                        \
        fmi2Status returned = inner.name(inst->component, vr, nvr, value);                       \
        if (returned == fmi2Fatal) inst->dead = 1;                                               \
        return worse(returned, inst->logged);                                                    \
    }
GET_OUTPUTS(fmi2GetReal, 'r', fmi2Real, AS_REAL, FITS_ANY)
GET_OUTPUTS(fmi2GetInteger, 'i', fmi2Integer, AS_INTEGER, FITS_INTEGER)
GET_OUTPUTS(fmi2GetBoolean, 'b', fmi2Boolean, AS_BOOLEAN, FITS_ANY)
FORWARD_VALUES(fmi2GetString, 's', 0,
               (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]))
FORWARD_VALUES(fmi2SetReal, 'r', 1,
               (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]))
FORWARD_VALUES(fmi2SetInteger, 'i', 1,
               (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]))
FORWARD_VALUES(fmi2SetBoolean, 'b', 1,
               (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]))
FORWARD_VALUES(fmi2SetString, 's', 1,
               (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]))

FORWARD(fmi2GetFMUstate, (fmi2Component c, fmi2FMUstate* state), inst->component, state)
FORWARD(fmi2SetFMUstate, (fmi2Component c, fmi2FMUstate state), inst->component, state)
FORWARD(fmi2FreeFMUstate, (fmi2Component c, fmi2FMUstate* state), inst->component, state)
FORWARD(fmi2SerializedFMUstateSize, (fmi2Component c, fmi2FMUstate state, size_t* size),
        inst->component, state, size)
FORWARD(fmi2SerializeFMUstate, (fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[], size_t size),
        inst->component, state, bytes, size)
FORWARD(fmi2DeSerializeFMUstate, (fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate* state),
        inst->component, bytes, size, state)

FORWARD(fmi2GetDirectionalDerivative,
        (fmi2Component c, const fmi2ValueReference vUnknown[], size_t nUnknown,
         const fmi2ValueReference vKnown[], size_t nKnown, const fmi2Real dvKnown[], fmi2Real dvUnknown[]),
        inst->component, vUnknown, nUnknown, vKnown, nKnown, dvKnown, dvUnknown)
FORWARD(fmi2SetRealInputDerivatives,
        (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer order[],
         const fmi2Real value[]),
        inst->component, vr, nvr, order, value)
FORWARD(fmi2GetRealOutputDerivatives,
        (fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer order[], fmi2Real value[]),
        inst->component, vr, nvr, order, value)

static void report_from_slave(void* context, int status, const char* category, const char* message)
{
    Instance* inst = (Instance*)context;
    shim_logger(inst, inst->name, (fmi2Status)status, category, message);
}

/* A plain doStep runs natively, through the Block's NativeStep record (no Python, no
 * GIL: python_slave_native_step); any other goes to the slave's do_step, called directly
 * (python_runtime.c says why).  Both with what pythonfmu would do around it: True is
 * fmi2OK, False fmi2Discard (raised to fmi2Error by the error the slave logged), and the
 * end of the last step taken kept for
 * fmi2GetRealStatus(fmi2LastSuccessfulTime) (a refused step leaves it, where pythonfmu
 * would record the refused step's start).  Without a claimed slave
 * (VIBROBLOCK_PYTHONFMU_DOSTEP=1, a slave that is no vibroblock facade, a Python without
 * the functions used) the call goes to pythonfmu. */
fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    Instance* inst = (Instance*)c;
    if (inst == NULL) return fmi2Error;
    inst->logged = fmi2OK;
    if (inst->dead) return refuse_dead(inst, "fmi2DoStep");
    if (inst->slave.do_step == NULL) {
        fmi2Status returned = inner.fmi2DoStep(inst->component, currentCommunicationPoint, communicationStepSize,
                                               noSetFMUStatePriorToCurrentPoint);
        if (returned == fmi2Fatal) inst->dead = 1;
        inst->stepped = 0;  /* pythonfmu's record is the current one again */
        return worse(returned, inst->logged);
    }
    int taken = python_slave_native_step(&inst->slave, currentCommunicationPoint, communicationStepSize) ||
                python_slave_do_step(&inst->slave, currentCommunicationPoint, communicationStepSize,
                                     report_from_slave, inst);
    if (taken) {
        inst->stepped = 1;
        inst->lastSuccessfulTime = currentCommunicationPoint + communicationStepSize;
    }
    return worse(taken ? fmi2OK : fmi2Discard, inst->logged);
}
FORWARD(fmi2CancelStep, (fmi2Component c), inst->component)

FORWARD(fmi2GetStatus, (fmi2Component c, const fmi2StatusKind s, fmi2Status* value), inst->component, s, value)

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real* value)
{
    Instance* inst = (Instance*)c;
    if (inst == NULL) return fmi2Error;
    inst->logged = fmi2OK;
    if (inst->dead) return refuse_dead(inst, "fmi2GetRealStatus");
    if (inst->stepped && s == fmi2LastSuccessfulTime && value != NULL) {
        *value = inst->lastSuccessfulTime;  /* the direct doStep's record (pythonfmu's is older) */
        return fmi2OK;
    }
    fmi2Status returned = inner.fmi2GetRealStatus(inst->component, s, value);
    if (returned == fmi2Fatal) inst->dead = 1;
    return worse(returned, inst->logged);
}
FORWARD(fmi2GetIntegerStatus, (fmi2Component c, const fmi2StatusKind s, fmi2Integer* value),
        inst->component, s, value)
FORWARD(fmi2GetBooleanStatus, (fmi2Component c, const fmi2StatusKind s, fmi2Boolean* value),
        inst->component, s, value)
FORWARD(fmi2GetStringStatus, (fmi2Component c, const fmi2StatusKind s, fmi2String* value),
        inst->component, s, value)
