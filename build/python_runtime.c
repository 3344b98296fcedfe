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
#include <stdarg.h>
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

static int bind_api(void* handle)
{
#define BIND(name) if ((*(void**)&py.name = dlsym(handle, #name)) == NULL) return 0;
    BIND(Py_IsInitialized) BIND(Py_InitializeEx) BIND(Py_SetProgramName) BIND(Py_DecodeLocale)
    BIND(PyEval_SaveThread) BIND(PyGILState_Ensure) BIND(PyGILState_Release) BIND(PyImport_ImportModule)
    BIND(PyErr_Fetch) BIND(PyObject_Str) BIND(PyUnicode_AsUTF8) BIND(Py_DecRef) BIND(PySys_GetObject)
    BIND(PyObject_CallMethod)
#undef BIND
    if ((py.Py_None = dlsym(handle, "_Py_NoneStruct")) == NULL) return 0;
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
