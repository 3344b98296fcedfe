/*
 * python_runtime.c - find and start the Python runtime behind the FMU.
 *
 * The library that runs the Python slave (pythonfmu's) refers to the Python C
 * API without naming a Python library, so it loads only into a process that
 * already holds one with global symbols (a Python host such as fmpy or
 * libcosimpy).  A host that is not a Python process gets "undefined symbol:
 * _Py_NoneStruct".  Before that library is loaded, python_runtime_ready()
 * makes sure the process has a usable Python:
 *
 *   - a Python already in the process and initialized (Python hosts) is used
 *     as it is;
 *   - otherwise the Python library of a configured environment is loaded with
 *     RTLD_GLOBAL and initialized as that environment's interpreter would be
 *     (its sys.prefix, site-packages), without signal handlers.
 *
 * Either way the modules the core needs must import, or the FMU refuses to
 * instantiate with a message saying what is missing and how to point it at a
 * Python environment.
 *
 * Where the environment is taken from, first found wins:
 *   1. the environment variable VIBROBLOCK_PYTHON;
 *   2. the file vibroblock-python.txt in the FMU's top folder (next to
 *      modelDescription.xml);
 *   3. the file $XDG_CONFIG_HOME/vibroblock/python.txt (~/.config/...);
 *   4. resources/python-environment.txt, written when the FMU was built (the
 *      build's virtual environment).
 * The variable holds a Python executable or an environment's folder.  A file
 * holds lines "python = <executable or folder>" and optionally
 * "library = <path of libpython3.X.so>"; a line without "=" is the python
 * entry; '#' starts a comment.  Without a library entry the library is looked
 * for next to the base interpreter (pyvenv.cfg's home) and in the system's
 * library folders.
 *
 * The interpreter started here is never finalized: extension modules such as
 * numba's do not survive Py_Finalize, and finalizing at process exit is what
 * makes other hosts abort.  It lives until the process ends.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <glob.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <wchar.h>

#include "python_runtime.h"

#define ENV_VARIABLE "VIBROBLOCK_PYTHON"
#define TOP_FOLDER_FILE "vibroblock-python.txt"
#define USER_FILE "vibroblock/python.txt"
#define RECORDED_FILE "resources/python-environment.txt"

static const char* const REQUIRED_MODULES[] = {"numpy", "numba"};

typedef void* PyObj;
typedef int PyGILState;

/* The C API functions used here; all are part of Python's stable ABI. */
static struct {
    int (*Py_IsInitialized)(void);
    void (*Py_InitializeEx)(int);
    void (*Py_SetProgramName)(const wchar_t*);
    wchar_t* (*Py_DecodeLocale)(const char*, size_t*);
    void* (*PyEval_SaveThread)(void);
    PyGILState (*PyGILState_Ensure)(void);
    void (*PyGILState_Release)(PyGILState);
    PyObj (*PyImport_ImportModule)(const char*);
    void (*PyErr_Fetch)(PyObj*, PyObj*, PyObj*);
    PyObj (*PyObject_Str)(PyObj);
    const char* (*PyUnicode_AsUTF8)(PyObj);
    void (*Py_DecRef)(PyObj);
    PyObj (*PySys_GetObject)(const char*);
    PyObj (*PyObject_CallMethod)(PyObj, const char*, const char*, ...);
    PyObj Py_None;
} py;

/* What python_slave_* use besides (also stable ABI, Python >= 3.2; PyObject_Vectorcall,
 * 3.9+, is taken when present: it calls without building an argument tuple).  Bound
 * apart: without them the FMU still works, its doSteps through pythonfmu. */
static struct {
    PyObj (*PyFloat_FromDouble)(double);
    PyObj (*PyObject_CallFunctionObjArgs)(PyObj, ...);
    PyObj (*PyObject_Vectorcall)(PyObj, PyObj const*, size_t, PyObj);
    PyObj (*PyObject_GetAttrString)(PyObj, const char*);
    int (*PyObject_IsTrue)(PyObj);
    long (*PyList_Size)(PyObj);
    PyObj (*PyList_GetItem)(PyObj, long);
    PyObj (*PyTuple_GetItem)(PyObj, long);
    long (*PyLong_AsLong)(PyObj);
    void* (*PyLong_AsVoidPtr)(PyObj);
    void (*PyErr_Clear)(void);
    int bound;
} slave_api;

static int bind_api(void* handle)
{
#define BIND(name) if ((*(void**)&py.name = dlsym(handle, #name)) == NULL) return 0;
    BIND(Py_IsInitialized) BIND(Py_InitializeEx) BIND(Py_SetProgramName) BIND(Py_DecodeLocale)
    BIND(PyEval_SaveThread) BIND(PyGILState_Ensure) BIND(PyGILState_Release) BIND(PyImport_ImportModule)
    BIND(PyErr_Fetch) BIND(PyObject_Str) BIND(PyUnicode_AsUTF8) BIND(Py_DecRef) BIND(PySys_GetObject)
    BIND(PyObject_CallMethod)
#undef BIND
    if ((py.Py_None = dlsym(handle, "_Py_NoneStruct")) == NULL) return 0;
#define BIND_SLAVE(name) *(void**)&slave_api.name = dlsym(handle, #name);
    BIND_SLAVE(PyFloat_FromDouble) BIND_SLAVE(PyObject_CallFunctionObjArgs) BIND_SLAVE(PyObject_Vectorcall)
    BIND_SLAVE(PyObject_GetAttrString) BIND_SLAVE(PyObject_IsTrue) BIND_SLAVE(PyList_Size)
    BIND_SLAVE(PyList_GetItem) BIND_SLAVE(PyTuple_GetItem) BIND_SLAVE(PyLong_AsLong) BIND_SLAVE(PyErr_Clear)
    BIND_SLAVE(PyLong_AsVoidPtr)
#undef BIND_SLAVE
    slave_api.bound = slave_api.PyFloat_FromDouble && slave_api.PyObject_CallFunctionObjArgs &&
                      slave_api.PyObject_GetAttrString && slave_api.PyObject_IsTrue && slave_api.PyList_Size &&
                      slave_api.PyList_GetItem && slave_api.PyTuple_GetItem && slave_api.PyLong_AsLong &&
                      slave_api.PyErr_Clear;
    return 1;
}

/* ---- text helpers --------------------------------------------------------- */

static void append(char* buffer, size_t size, const char* format, ...)
{
    size_t used = strlen(buffer);
    if (used + 1 >= size) return;
    va_list args;
    va_start(args, format);
    vsnprintf(buffer + used, size - used, format, args);
    va_end(args);
}

static char* trim(char* s)
{
    while (*s == ' ' || *s == '\t') s++;
    char* end = s + strlen(s);
    while (end > s && (end[-1] == ' ' || end[-1] == '\t' || end[-1] == '\n' || end[-1] == '\r')) *--end = '\0';
    return s;
}

static int is_file(const char* path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static int is_dir(const char* path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

static void parent_of(char* path)
{
    char* slash = strrchr(path, '/');
    if (slash == NULL) strcpy(path, ".");
    else if (slash == path) path[1] = '\0';
    else *slash = '\0';
}

/* ---- configuration ----------------------------------------------------------- */

typedef struct {
    char source[PATH_MAX + 128]; /* where the setting came from, for messages */
    char python[PATH_MAX];       /* executable or environment folder, as given */
    char library[PATH_MAX];      /* libpython, if given */
} Setting;

/* 1: read, 0: no such file, -1: unreadable or without a python entry (message in error). */
static int read_setting_file(const char* path, Setting* setting, char* error, size_t size)
{
    FILE* file = fopen(path, "r");
    if (file == NULL) return 0;
    memset(setting, 0, sizeof *setting);
    snprintf(setting->source, sizeof setting->source, "the file %s", path);
    char line[PATH_MAX + 64];
    while (fgets(line, sizeof line, file) != NULL) {
        char* hash = strchr(line, '#');
        if (hash != NULL) *hash = '\0';
        char* text = trim(line);
        if (*text == '\0') continue;
        char* equals = strchr(text, '=');
        if (equals == NULL) {
            snprintf(setting->python, sizeof setting->python, "%s", text);
            continue;
        }
        *equals = '\0';
        char* key = trim(text);
        char* value = trim(equals + 1);
        if (strcmp(key, "python") == 0) snprintf(setting->python, sizeof setting->python, "%s", value);
        else if (strcmp(key, "library") == 0) snprintf(setting->library, sizeof setting->library, "%s", value);
    }
    fclose(file);
    if (setting->python[0] == '\0' && setting->library[0] == '\0') {
        append(error, size, "%s names no Python (expected a line \"python = /path/to/environment\"). ", path);
        return -1;
    }
    return 1;
}

/* The first configured setting; 0 if there is none (what was looked at is in `looked`). */
static int find_setting(const char* fmu_root, Setting* setting, char* error, size_t size,
                        char* looked, size_t looked_size)
{
    const char* variable = getenv(ENV_VARIABLE);
    if (variable != NULL && *variable != '\0') {
        memset(setting, 0, sizeof *setting);
        snprintf(setting->source, sizeof setting->source, "the environment variable %s", ENV_VARIABLE);
        snprintf(setting->python, sizeof setting->python, "%s", variable);
        return 1;
    }
    append(looked, looked_size, "%s is not set; ", ENV_VARIABLE);

    char path[PATH_MAX + 64];
    const char* files[3];
    char top[PATH_MAX + 64], user[PATH_MAX + 64], recorded[PATH_MAX + 64];
    snprintf(top, sizeof top, "%s/%s", fmu_root, TOP_FOLDER_FILE);
    const char* config_home = getenv("XDG_CONFIG_HOME");
    const char* home = getenv("HOME");
    if (config_home != NULL && *config_home != '\0') snprintf(user, sizeof user, "%s/%s", config_home, USER_FILE);
    else snprintf(user, sizeof user, "%s/.config/%s", home != NULL ? home : "", USER_FILE);
    snprintf(recorded, sizeof recorded, "%s/%s", fmu_root, RECORDED_FILE);
    files[0] = top;
    files[1] = user;
    files[2] = recorded;
    for (int i = 0; i < 3; i++) {
        snprintf(path, sizeof path, "%s", files[i]);
        int found = read_setting_file(path, setting, error, size);
        if (found != 0) return found;
        append(looked, looked_size, "no %s; ", path);
    }
    return 0;
}

/* ---- from a setting to an executable and a library ---------------------------- */

/* pyvenv.cfg of the environment `executable` belongs to, if any: fills home and version. */
static void read_pyvenv(const char* executable, char* home, char* version)
{
    char dir[PATH_MAX], cfg[PATH_MAX + 16];
    snprintf(dir, sizeof dir, "%s", executable);
    parent_of(dir);
    for (int up = 0; up < 2; up++) {
        snprintf(cfg, sizeof cfg, "%s/pyvenv.cfg", dir);
        FILE* file = fopen(cfg, "r");
        if (file != NULL) {
            char line[PATH_MAX + 64];
            while (fgets(line, sizeof line, file) != NULL) {
                char* equals = strchr(line, '=');
                if (equals == NULL) continue;
                *equals = '\0';
                char* key = trim(line);
                char* value = trim(equals + 1);
                if (strcmp(key, "home") == 0) snprintf(home, PATH_MAX, "%s", value);
                else if (strcmp(key, "version") == 0 || strcmp(key, "version_info") == 0)
                    snprintf(version, 32, "%s", value);
            }
            fclose(file);
            return;
        }
        parent_of(dir);
    }
}

/* "3.11.7" -> "3.11" */
static void major_minor(char* version)
{
    char* dot = strchr(version, '.');
    if (dot != NULL && (dot = strchr(dot + 1, '.')) != NULL) *dot = '\0';
}

static int first_match(const char* pattern, char* out)
{
    glob_t found;
    int ok = glob(pattern, 0, NULL, &found) == 0 && found.gl_pathc > 0;
    if (ok) snprintf(out, PATH_MAX, "%s", found.gl_pathv[found.gl_pathc - 1]);
    globfree(&found);
    return ok;
}

/* Fill executable and library from a setting; 0 with a message on failure. */
static int resolve(const Setting* setting, char* executable, char* library, char* error, size_t size)
{
    executable[0] = library[0] = '\0';
    if (setting->python[0] != '\0') {
        if (is_dir(setting->python)) {
            const char* names[] = {"bin/python3", "bin/python"};
            for (int i = 0; i < 2 && executable[0] == '\0'; i++) {
                int n = snprintf(executable, PATH_MAX, "%s/%s", setting->python, names[i]);
                if (n >= PATH_MAX || !is_file(executable)) executable[0] = '\0';
            }
            if (executable[0] == '\0') {
                append(error, size, "%s names the folder %s, which has no bin/python3. ", setting->source,
                       setting->python);
                return 0;
            }
        } else if (is_file(setting->python)) {
            snprintf(executable, PATH_MAX, "%s", setting->python);
        } else {
            append(error, size, "%s names %s, which does not exist. ", setting->source, setting->python);
            return 0;
        }
    }
    if (setting->library[0] != '\0') {
        if (!is_file(setting->library)) {
            append(error, size, "%s names the Python library %s, which does not exist. ", setting->source,
                   setting->library);
            return 0;
        }
        snprintf(library, PATH_MAX, "%s", setting->library);
        return 1;
    }

    char home[PATH_MAX] = "", version[32] = "", real[PATH_MAX];
    read_pyvenv(executable, home, version);
    if (home[0] == '\0') {
        if (realpath(executable, real) == NULL) snprintf(real, sizeof real, "%s", executable);
        snprintf(home, sizeof home, "%s", real);
        parent_of(home);
        const char* base = strrchr(real, '/');
        base = base != NULL ? base + 1 : real;
        if (strncmp(base, "python3.", 7) == 0) snprintf(version, sizeof version, "%s", base + 6);
    }
    major_minor(version);
    const char* version_glob = version[0] != '\0' ? version : "3.*";
    const char* folders[] = {"%s/../lib", "%s/../lib64", NULL};
    char pattern[PATH_MAX + 64];
    for (int i = 0; folders[i] != NULL; i++) {
        char folder[PATH_MAX];
        snprintf(folder, sizeof folder, folders[i], home);
        snprintf(pattern, sizeof pattern, "%s/libpython%s.so.1.0", folder, version_glob);
        if (first_match(pattern, library)) return 1;
        snprintf(pattern, sizeof pattern, "%s/libpython%s.so", folder, version_glob);
        if (first_match(pattern, library)) return 1;
    }
    const char* system_folders[] = {"/usr/lib/x86_64-linux-gnu", "/usr/lib64", "/usr/lib", "/usr/local/lib", NULL};
    for (int i = 0; system_folders[i] != NULL; i++) {
        snprintf(pattern, sizeof pattern, "%s/libpython%s.so.1.0", system_folders[i], version_glob);
        if (first_match(pattern, library)) return 1;
    }
    append(error, size,
           "%s names the Python %s, but no shared Python library (libpython%s.so) was found next to its "
           "base interpreter (%s/../lib) or in the system's library folders; such a Python cannot be "
           "embedded: use one built with --enable-shared or the system's python3, or give the library's "
           "path as \"library = ...\" in a settings file. ",
           setting->source, executable, version_glob, home);
    return 0;
}

/* ---- start and check ------------------------------------------------------------ */

/* Find the modules the core needs, without importing them (the core sets numba's
 * cache folder before numba is first imported); 0 with a message naming the
 * missing one. */
static int check_modules(const char* who, char* error, size_t size)
{
    int ok = 1;
    PyGILState gil = py.PyGILState_Ensure();
    PyObj util = py.PyImport_ImportModule("importlib.util");
    for (size_t i = 0; ok && i < sizeof REQUIRED_MODULES / sizeof *REQUIRED_MODULES; i++) {
        PyObj spec = util != NULL ? py.PyObject_CallMethod(util, "find_spec", "s", REQUIRED_MODULES[i]) : NULL;
        int found = spec != NULL && spec != py.Py_None;
        if (spec != NULL) py.Py_DecRef(spec);
        if (found) continue;
        ok = 0;
        PyObj type = NULL, value = NULL, traceback = NULL;
        py.PyErr_Fetch(&type, &value, &traceback);
        const char* reason = "no module of that name on sys.path";
        PyObj text = value != NULL ? py.PyObject_Str(value) : NULL;
        if (text != NULL) {
            const char* utf8 = py.PyUnicode_AsUTF8(text);
            if (utf8 != NULL) reason = utf8;
        }
        char prefix[PATH_MAX] = "?";
        PyObj sys_prefix = py.PySys_GetObject("prefix");  /* borrowed */
        if (sys_prefix != NULL) {
            const char* utf8 = py.PyUnicode_AsUTF8(sys_prefix);
            if (utf8 != NULL) snprintf(prefix, sizeof prefix, "%s", utf8);
        }
        append(error, size, "%s (sys.prefix %s) cannot find %s, which the FMU needs: %s. ", who, prefix,
               REQUIRED_MODULES[i], reason);
        if (text != NULL) py.Py_DecRef(text);
        if (type != NULL) py.Py_DecRef(type);
        if (value != NULL) py.Py_DecRef(value);
        if (traceback != NULL) py.Py_DecRef(traceback);
    }
    if (util != NULL) py.Py_DecRef(util);
    py.PyGILState_Release(gil);
    return ok;
}

static void how_to_fix(char* error, size_t size)
{
    append(error, size,
           "To point the FMU at a Python 3 environment that has numpy and numba (e.g. the project's .venv, "
           "or any environment after \"pip install numpy numba\"): set the environment variable %s to the "
           "environment's folder or its bin/python, or write \"python = /path/to/environment\" into %s in the "
           "FMU's top folder (next to modelDescription.xml) or into ~/.config/%s.",
           ENV_VARIABLE, TOP_FOLDER_FILE, USER_FILE);
}

int python_runtime_ready(const char* fmu_root, char* error, size_t size)
{
    error[0] = '\0';

    /* A Python already in the process (a Python host, or an FMU loaded earlier). */
    void* present = dlsym(RTLD_DEFAULT, "Py_IsInitialized");
    if (present != NULL && ((int (*)(void))present)()) {
        if (!bind_api(RTLD_DEFAULT)) {
            append(error, size, "the Python in this process lacks functions of the Python C API. ");
            return 0;
        }
        if (check_modules("the Python of this process", error, size)) return 1;
        how_to_fix(error, size);
        return 0;
    }

    Setting setting;
    char looked[4 * PATH_MAX] = "";
    int found = find_setting(fmu_root, &setting, error, size, looked, sizeof looked);
    if (found <= 0) {
        if (found == 0)
            append(error, size, "No Python environment is configured for this FMU (%s). ", looked);
        how_to_fix(error, size);
        return 0;
    }
    char executable[PATH_MAX], library[PATH_MAX];
    if (!resolve(&setting, executable, library, error, size)) {
        how_to_fix(error, size);
        return 0;
    }
    void* handle = dlopen(library, RTLD_NOW | RTLD_GLOBAL);
    if (handle == NULL) {
        append(error, size, "cannot load the Python library %s (from %s): %s. ", library, setting.source,
               dlerror());
        how_to_fix(error, size);
        return 0;
    }
    if (!bind_api(handle)) {
        append(error, size, "%s (from %s) is not a Python 3 library with the functions this FMU uses. ",
               library, setting.source);
        how_to_fix(error, size);
        return 0;
    }
    if (!py.Py_IsInitialized()) {
        /* As that environment's interpreter: sys.prefix and site-packages follow from
         * the executable's location (pyvenv.cfg).  Kept for the process's lifetime. */
        if (executable[0] != '\0') {
            wchar_t* program = py.Py_DecodeLocale(executable, NULL);
            if (program != NULL) py.Py_SetProgramName(program);
        }
        py.Py_InitializeEx(0);  /* no signal handlers: the host owns them */
        py.PyEval_SaveThread();  /* the FMU's calls take the GIL as they need it */
    }
    char who[2 * PATH_MAX + 128];
    snprintf(who, sizeof who, "the Python %s (from %s)", executable[0] ? executable : library, setting.source);
    if (check_modules(who, error, size)) return 1;
    how_to_fix(error, size);
    return 0;
}

/* ---- a slave's doStep, called directly ---------------------------------------- */

/* pythonfmu 0.7.0 answers every fmi2DoStep with PyObject_CallMethod(slave, "do_step",
 * "(dd)", ...) and then a scan of the slave's log queue that builds four attribute-name
 * strings each time: some 0.5 us a call, a few percent of a doStep of a thousand
 * internal steps.  The front end calls the slave's bound do_step itself instead (the
 * same Python call, so the same results and FMU state), and reads the log queue only
 * when it holds something.  Everything else stays with pythonfmu.  The slave is handed
 * over by vibroblock.fmi (_claim_slave): the one its FmuFacade.__init__ registered on
 * this thread while pythonfmu made it, if its instance name and resource folder are the
 * ones given to pythonfmu.  A slave that is not a vibroblock facade (no such module or
 * no such slave) keeps pythonfmu's doStep. */

/* ---- a doStep without Python ------------------------------------------------------ */

/* The record a Block keeps for a front end (vibroblock/native.py, NativeStep: the same
 * fields in the same order; LAYOUT there is NATIVE_LAYOUT here). */
#define NATIVE_LAYOUT 3
#define OUTPUT_SURFACE_Z (-1) /* native.SURFACE_Z: z + penetration / cos(alpha) */
#define OUTPUT_ZERO (-2)      /* native.ZERO */
typedef struct {
    int64_t layout;
    int64_t ready;    /* a run has started and its advance kernel is bound */
    int64_t held;     /* an input waits to be applied by the slave */
    int64_t (*advance)(int64_t kind, int64_t flags, double* y, int64_t* cnt, double* drv, double* prm, int64_t n_steps,
                       int64_t track_energy);
    int64_t returned_ok;
    int64_t kind;     /* the run's variant, readings and laws (vibroblock/readings.py) */
    int64_t flags;
    double* y;
    int64_t* cnt;
    double* drv;
    double* prm;
    int64_t step_slot;
    int64_t track_energy;
    double step_budget;
    double t0, dt;
    double time;
    double grid_tolerance, time_tolerance;
    int64_t (*observe)(int64_t kind, int64_t flags, double* y, int64_t* cnt, double* drv, double* prm, double h,
                       int64_t track_energy, double* obs);
    int64_t observed_ok;     /* what observe returns when it filled obs */
    double* obs;
    const int64_t* outputs;  /* n_outputs pairs (value reference, observation slot or OUTPUT_*) */
    int64_t n_outputs;
} NativeStep;

/* Observation slots the computed outputs use: vibroblock/layout.py's O_*, which the FMU
 * tests hold to (surface_z read here and through pythonfmu, compared bit for bit). */
enum { O_Z = 1, O_PENETRATION = 5, O_COS = 7, N_OBS = 16 };

/* The slave's record (its attribute native_step, the address), or NULL. */
static void* claim_native_step(PyObj slave)
{
    if (slave_api.PyLong_AsVoidPtr == NULL) return NULL;
    PyObj address = slave_api.PyObject_GetAttrString(slave, "native_step");
    NativeStep* record = address != NULL ? (NativeStep*)slave_api.PyLong_AsVoidPtr(address) : NULL;
    if (address != NULL) py.Py_DecRef(address);
    slave_api.PyErr_Clear();
    return record != NULL && record->layout == NATIVE_LAYOUT ? record : NULL;
}

/* Block.advance_to(t + h) for the request the slave's do_step takes straight to it (a
 * started run with no input waiting, at the block's own time up to the slave's
 * tolerance, 0 < h < inf), with the same arithmetic, so the same grid steps and bits.
 * Anything else, and a kernel call that does not simply finish (a failure, which leaves
 * the state as it was; a scene's guard stopping early, which keeps the steps taken; a
 * kernel that raised), is left to the slave's do_step, which starts from the state the
 * call left and says what is wrong.  No Python runs here, so no GIL is taken. */
int python_slave_native_step(const PythonSlave* slave, double t, double h)
{
    NativeStep* n = (NativeStep*)slave->native;
    if (n == NULL || !n->ready || n->held || !(0.0 < h && h < INFINITY)) return 0;
    double now = n->time;
    if (!(t == now || fabs(t - now) <= n->time_tolerance * fmax(1.0, fabs(now)))) return 0;
    double end = now + h;
    if (!(now < end && end < INFINITY)) return 0;
    double target = floor((end - n->t0) / n->dt + n->grid_tolerance);
    double step = (double)n->cnt[n->step_slot];
    if (!(target - step <= n->step_budget) || target >= 9.2e18) return 0;  /* (beyond int64: Python refuses) */
    if (target > step &&
        n->advance(n->kind, n->flags, n->y, n->cnt, n->drv, n->prm, (int64_t)target - (int64_t)step, n->track_energy)
            != n->returned_ok)
        return 0;
    n->time = end;
    return 1;
}

/* The slave's Block outputs for a read whose value references are all in the record's
 * table: Block._observe's time within the grid step, one call of the observe kernel, and
 * Block._observables' arithmetic, so the same bits (an Integer or Boolean output as the
 * double its slot holds; the caller converts).  0 (values undefined) when the read must
 * go to the slave: a reference not in the table, no run started, a kernel that raised,
 * or a value that is not finite (the slave's read is then the one on record). */
int python_slave_native_get(const PythonSlave* slave, const unsigned int vr[], size_t nvr, double values[])
{
    NativeStep* n = (NativeStep*)slave->native;
    if (n == NULL || !n->ready || n->observe == NULL || n->obs == NULL || n->outputs == NULL) return 0;
    int64_t source[64];
    if (nvr > sizeof source / sizeof source[0]) return 0;
    for (size_t i = 0; i < nvr; i++) {
        int64_t k = 0;
        while (k < n->n_outputs && n->outputs[2 * k] != (int64_t)vr[i]) k++;
        if (k == n->n_outputs) return 0;
        source[i] = n->outputs[2 * k + 1];
        if (source[i] >= N_OBS || source[i] < OUTPUT_ZERO) return 0;
    }
    double grid_time = n->t0 + (double)n->cnt[n->step_slot] * n->dt;
    double h = n->time - grid_time;
    if (h < n->grid_tolerance * n->dt) h = 0.0;  /* on the grid up to rounding of the master's time */
    if (n->observe(n->kind, n->flags, n->y, n->cnt, n->drv, n->prm, fmin(h, n->dt), n->track_energy, n->obs) !=
        n->observed_ok)
        return 0;
    const double* obs = n->obs;
    for (size_t i = 0; i < nvr; i++) {
        double value = source[i] >= 0               ? obs[source[i]]
                       : source[i] == OUTPUT_ZERO    ? 0.0
                                                     : obs[O_Z] + obs[O_PENETRATION] / obs[O_COS];
        if (!isfinite(value)) return 0;
        values[i] = value;
    }
    return 1;
}

int python_slave_claim(PythonSlave* slave, const char* instance_name, const char* resource_location)
{
    memset(slave, 0, sizeof *slave);
    if (!slave_api.bound) return 0;
    const char* off = getenv("VIBROBLOCK_PYTHONFMU_DOSTEP");  /* "1": every doStep through pythonfmu */
    if (off != NULL && strcmp(off, "1") == 0) return 0;
    PyGILState gil = py.PyGILState_Ensure();
    PyObj module = py.PyImport_ImportModule("vibroblock.fmi");
    PyObj made = module != NULL ? py.PyObject_CallMethod(module, "_claim_slave", "ss", instance_name != NULL ? instance_name : "",
                                                        resource_location != NULL ? resource_location : "") : NULL;
    if (made != NULL && made != py.Py_None) {
        slave->do_step = slave_api.PyObject_GetAttrString(made, "do_step");
        slave->log_queue = slave->do_step != NULL ? slave_api.PyObject_GetAttrString(made, "log_queue") : NULL;
        if (slave->log_queue != NULL && slave_api.PyList_Size(slave->log_queue) < 0) {  /* not a list */
            py.Py_DecRef(slave->log_queue);
            slave->log_queue = NULL;
        }
        if (slave->log_queue != NULL) {
            slave->slave = made;
            made = NULL;
            slave->native = claim_native_step(slave->slave);
        } else if (slave->do_step != NULL) {
            py.Py_DecRef(slave->do_step);
            slave->do_step = NULL;
        }
    }
    if (made != NULL) py.Py_DecRef(made);
    if (module != NULL) py.Py_DecRef(module);
    slave_api.PyErr_Clear();  /* nothing found is no error: pythonfmu's path is used */
    py.PyGILState_Release(gil);
    return slave->slave != NULL;
}

void python_slave_release(PythonSlave* slave)
{
    if (slave->slave == NULL) return;
    PyGILState gil = py.PyGILState_Ensure();
    py.Py_DecRef(slave->do_step);
    py.Py_DecRef(slave->log_queue);
    py.Py_DecRef(slave->slave);
    py.PyGILState_Release(gil);
    memset(slave, 0, sizeof *slave);
}

/* The exception set now as text, cleared. */
static void report_exception(PythonSlaveReport report, void* context, const char* what)
{
    PyObj type = NULL, value = NULL, traceback = NULL;
    py.PyErr_Fetch(&type, &value, &traceback);
    PyObj text = value != NULL ? py.PyObject_Str(value) : type != NULL ? py.PyObject_Str(type) : NULL;
    const char* utf8 = text != NULL ? py.PyUnicode_AsUTF8(text) : NULL;
    char message[1024];
    snprintf(message, sizeof message, "%s: %s; the FMU's state is as the failed call left it",
             what, utf8 != NULL ? utf8 : "an exception without a message");
    slave_api.PyErr_Clear();
    report(context, 3 /* fmi2Error */, "logStatusError", message);
    if (text != NULL) py.Py_DecRef(text);
    if (type != NULL) py.Py_DecRef(type);
    if (value != NULL) py.Py_DecRef(value);
    if (traceback != NULL) py.Py_DecRef(traceback);
}

/* The slave's queued messages, passed on in order and taken off its queue. */
static void report_messages(const PythonSlave* slave, PythonSlaveReport report, void* context)
{
    PyObj messages = py.PyObject_CallMethod(slave->slave, "_take_log", NULL);
    long n = messages != NULL ? slave_api.PyList_Size(messages) : -1;
    if (n < 0) {
        report_exception(report, context, "doStep: cannot read the FMU's log messages");
        if (messages != NULL) py.Py_DecRef(messages);
        return;
    }
    for (long i = 0; i < n; i++) {
        PyObj entry = slave_api.PyList_GetItem(messages, i);  /* borrowed, as the items below */
        PyObj status = entry != NULL ? slave_api.PyTuple_GetItem(entry, 0) : NULL;
        PyObj category = entry != NULL ? slave_api.PyTuple_GetItem(entry, 1) : NULL;
        PyObj text = entry != NULL ? slave_api.PyTuple_GetItem(entry, 2) : NULL;
        long level = status != NULL ? slave_api.PyLong_AsLong(status) : 3;
        const char* category_utf8 = category != NULL ? py.PyUnicode_AsUTF8(category) : NULL;
        const char* text_utf8 = text != NULL ? py.PyUnicode_AsUTF8(text) : NULL;
        if (level < 0 || level > 4) level = 3;  /* not an fmi2Status: an error */
        slave_api.PyErr_Clear();
        report(context, (int)level, category_utf8 != NULL && category_utf8[0] ? category_utf8 : "logAll",
               text_utf8 != NULL ? text_utf8 : "(a log message that is not text)");
    }
    py.Py_DecRef(messages);
}

int python_slave_do_step(const PythonSlave* slave, double t, double h, PythonSlaveReport report, void* context)
{
    PyGILState gil = py.PyGILState_Ensure();
    int taken = 0;
    PyObj args[2] = {slave_api.PyFloat_FromDouble(t), slave_api.PyFloat_FromDouble(h)};
    PyObj result = NULL;
    if (args[0] != NULL && args[1] != NULL)
        result = slave_api.PyObject_Vectorcall != NULL
                     ? slave_api.PyObject_Vectorcall(slave->do_step, args, 2, NULL)
                     : slave_api.PyObject_CallFunctionObjArgs(slave->do_step, args[0], args[1], NULL);
    for (int i = 0; i < 2; i++)
        if (args[i] != NULL) py.Py_DecRef(args[i]);
    if (result != NULL) {
        taken = slave_api.PyObject_IsTrue(result) == 1;
        py.Py_DecRef(result);
        slave_api.PyErr_Clear();
    } else {
        /* The facades catch every Exception; what gets here (MemoryError in the
         * interpreter, a BaseException) is reported, never passed on to the host. */
        report_exception(report, context, "doStep: internal error in the Python slave");
    }
    if (slave_api.PyList_Size(slave->log_queue) > 0) report_messages(slave, report, context);
    py.PyGILState_Release(gil);
    return taken;
}
