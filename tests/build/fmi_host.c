/*
 * fmi_host.c - a minimal FMI 2.0 co-simulation master with no Python in it.
 *
 * It loads an extracted FMU's binaries/linux64/<id>.so with dlopen, as FMI tool
 * chains do (OMSimulator, Simulink, C++ masters), and drives it.  The test suite
 * (tests/build/test_c_host.py) compiles it with cc and compares what it prints
 * with fmpy.  Commands (DIR: extracted FMU; ID: modelIdentifier):
 *
 *   run DIR ID GUID START STOP STEP [options]   simulate like fmpy's simulate_fmu and
 *       print "time value..." per communication point, reals as exact hex floats.
 *       -r VR VALUE / -i VR VALUE / -b VR VALUE   start values (before initialization)
 *       -p NAME VALUE                              a start value by the variable's name, typed
 *                                                  as modelDescription.xml declares it; an
 *                                                  Integer switch also takes one of the names
 *                                                  its description lists ("3 = rate_state_aging")
 *       -o r|i|b VR                                an output column
 *       -d VRZ VRV VRA AMP OMEGA                   drive three inputs before each step with
 *                                                  AMP sin(OMEGA t) and its two derivatives
 *   choices DIR NAME                              the names -p accepts for Integer NAME, one
 *                                                  "value name" per line
 *   check DIR ID GUID VR_X VR_PARAM START_VALUE   the calls FMI 2.0 requires (see check())
 *   cycles DIR ID GUID N VR_OUT                   N instantiate/step/free cycles; prints RSS
 *   multi ID:DIR:GUID:VR ...                      all FMUs, two instances each, one process;
 *                                                  VR: first of plate_z, plate_v, plate_a
 *
 *   bench DIR ID GUID H N VR...                   seconds from process start to the first doStep's
 *                                                  end, then per doStep of H and per output read:
 *                                                  the mean over N doSteps and the mean of the
 *                                                  quietest block of BENCH_BLOCK doSteps (on a
 *                                                  shared machine the load of others varies)
 *
 * Exit status 0 when everything held; failed checks are printed as "FAIL ...".
 */
#define _GNU_SOURCE
#include <ctype.h>
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

typedef void* fmi2Component;
typedef unsigned int fmi2ValueReference;
typedef int fmi2Status; /* 0 OK, 1 Warning, 2 Discard, 3 Error, 4 Fatal */
enum { OK = 0, WARNING = 1, ERROR = 3 };
typedef struct {
    void (*logger)(void*, const char*, int, const char*, const char*, ...);
    void* (*allocateMemory)(size_t, size_t);
    void (*freeMemory)(void*);
    void (*stepFinished)(void*, int);
    void* componentEnvironment;
} Callbacks;

/* Every function a co-simulation FMU must export (FMI 2.0, sections 2.1 and 4.2). */
#define API(X)                                                                                     \
    X(const char* (*)(void), fmi2GetTypesPlatform) X(const char* (*)(void), fmi2GetVersion)         \
    X(int (*)(fmi2Component, int, size_t, const char* const*), fmi2SetDebugLogging)                 \
    X(fmi2Component (*)(const char*, int, const char*, const char*, const Callbacks*, int, int),   \
      fmi2Instantiate)                                                                             \
    X(void (*)(fmi2Component), fmi2FreeInstance)                                                   \
    X(int (*)(fmi2Component, int, double, double, int, double), fmi2SetupExperiment)               \
    X(int (*)(fmi2Component), fmi2EnterInitializationMode)                                         \
    X(int (*)(fmi2Component), fmi2ExitInitializationMode) X(int (*)(fmi2Component), fmi2Terminate) \
    X(int (*)(fmi2Component), fmi2Reset)                                                           \
    X(int (*)(fmi2Component, const fmi2ValueReference*, size_t, double*), fmi2GetReal)             \
    X(int (*)(fmi2Component, const fmi2ValueReference*, size_t, int*), fmi2GetInteger)             \
    X(int (*)(fmi2Component, const fmi2ValueReference*, size_t, int*), fmi2GetBoolean)             \
    X(void*, fmi2GetString)                                                                        \
    X(int (*)(fmi2Component, const fmi2ValueReference*, size_t, const double*), fmi2SetReal)       \
    X(int (*)(fmi2Component, const fmi2ValueReference*, size_t, const int*), fmi2SetInteger)       \
    X(int (*)(fmi2Component, const fmi2ValueReference*, size_t, const int*), fmi2SetBoolean)       \
    X(void*, fmi2SetString)                                                                        \
    X(int (*)(fmi2Component, void**), fmi2GetFMUstate) X(int (*)(fmi2Component, void*), fmi2SetFMUstate) \
    X(int (*)(fmi2Component, void**), fmi2FreeFMUstate)                                            \
    X(int (*)(fmi2Component, void*, size_t*), fmi2SerializedFMUstateSize)                          \
    X(int (*)(fmi2Component, void*, char*, size_t), fmi2SerializeFMUstate)                         \
    X(int (*)(fmi2Component, const char*, size_t, void**), fmi2DeSerializeFMUstate)                \
    X(int (*)(fmi2Component, const fmi2ValueReference*, size_t, const fmi2ValueReference*, size_t, \
              const double*, double*), fmi2GetDirectionalDerivative)                               \
    X(int (*)(fmi2Component, const fmi2ValueReference*, size_t, const int*, const double*),        \
      fmi2SetRealInputDerivatives)                                                                 \
    X(void*, fmi2GetRealOutputDerivatives)                                                         \
    X(int (*)(fmi2Component, double, double, int), fmi2DoStep) X(int (*)(fmi2Component), fmi2CancelStep) \
    X(int (*)(fmi2Component, int, int*), fmi2GetStatus)                                            \
    X(int (*)(fmi2Component, int, double*), fmi2GetRealStatus)                                     \
    X(void*, fmi2GetIntegerStatus) X(void*, fmi2GetBooleanStatus) X(void*, fmi2GetStringStatus)

typedef struct {
    void* handle;
#define FIELD(type, name) __typeof__(type) name;
    API(FIELD)
} Fmu;

static int failures = 0;
static int errors_logged = 0;
static char last_message[4096];

#define CHECK(cond, ...)                                                  \
    do {                                                                  \
        if (!(cond)) {                                                    \
            failures++;                                                   \
            printf("FAIL %s:%d %s: ", __FILE__, __LINE__, #cond);         \
            printf(__VA_ARGS__);                                          \
            printf("\n");                                                 \
        }                                                                 \
    } while (0)

static void logger(void* env, const char* instance, int status, const char* category, const char* format, ...)
{
    (void)env;
    va_list args;
    va_start(args, format);
    vsnprintf(last_message, sizeof last_message, format, args);
    va_end(args);
    if (status >= ERROR) errors_logged++;
    fprintf(stderr, "[%s] %d %s: %s\n", instance ? instance : "?", status, category ? category : "", last_message);
}

static const Callbacks callbacks = {logger, calloc, free, NULL, NULL};

static void load(Fmu* fmu, const char* dir, const char* id)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/binaries/linux64/%s.so", dir, id);
    memset(fmu, 0, sizeof *fmu);
    fmu->handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (fmu->handle == NULL) {
        printf("FAIL cannot load %s: %s\n", path, dlerror());
        exit(2);
    }
#define BIND(type, name)                                              \
    *(void**)&fmu->name = dlsym(fmu->handle, #name);                  \
    CHECK(fmu->name != NULL, "%s does not export %s", path, #name);
    API(BIND)
    if (failures) exit(1);
}

static fmi2Component instantiate(const Fmu* fmu, const char* name, const char* dir, const char* guid)
{
    char uri[4200];
    snprintf(uri, sizeof uri, "file://%s/resources", dir);
    return fmu->fmi2Instantiate(name, 1 /* fmi2CoSimulation */, guid, uri, &callbacks, 0, 0);
}

/* ---- variables by name, from the FMU's own modelDescription.xml ------------------ */

/* One ScalarVariable: its name, value reference, type element and description, with
 * XML's character references decoded. */
typedef struct {
    char* name;
    char* description;
    char type[16]; /* Real, Integer, Boolean, String, Enumeration */
    fmi2ValueReference vr;
} Variable;

typedef struct {
    char* model_name;
    Variable* variables;
    int count;
} ModelDescription;

static char* read_file(const char* path)
{
    FILE* f = fopen(path, "rb");
    if (f == NULL) return NULL;
    size_t size = 0, cap = 1 << 16;
    char* text = malloc(cap);
    for (size_t got; text != NULL && (got = fread(text + size, 1, cap - size - 1, f)) > 0;) {
        size += got;
        if (size + 1 == cap) text = realloc(text, cap *= 2);
    }
    fclose(f);
    if (text != NULL) text[size] = '\0';
    return text;
}

/* The text of an attribute value with &lt; &gt; &amp; &quot; &apos; &#N; &#xN; decoded. */
static char* xml_text(const char* from, size_t length)
{
    char* out = malloc(length + 1);
    size_t n = 0;
    for (size_t i = 0; i < length;) {
        static const struct { const char* entity; char c; } named[] = {
            {"&lt;", '<'}, {"&gt;", '>'}, {"&amp;", '&'}, {"&quot;", '"'}, {"&apos;", '\''}};
        int done = 0;
        for (size_t k = 0; k < sizeof named / sizeof named[0] && !done; k++) {
            size_t len = strlen(named[k].entity);
            if (i + len <= length && strncmp(from + i, named[k].entity, len) == 0) {
                out[n++] = named[k].c;
                i += len;
                done = 1;
            }
        }
        if (!done && from[i] == '&' && i + 2 < length && from[i + 1] == '#') {
            char* end = NULL;
            int hex = from[i + 2] == 'x' || from[i + 2] == 'X';
            long code = strtol(from + i + (hex ? 3 : 2), &end, hex ? 16 : 10);
            if (end != NULL && end < from + length && *end == ';' && code > 0 && code < 128) {
                out[n++] = (char)code; /* the descriptions' separators are ASCII; others stay as written */
                i = (size_t)(end - from) + 1;
                done = 1;
            }
        }
        if (!done) out[n++] = from[i++];
    }
    out[n] = '\0';
    return out;
}

/* The value of attribute NAME in the start tag [tag, end), or NULL. */
static char* attribute(const char* tag, const char* end, const char* name)
{
    size_t len = strlen(name);
    for (const char* p = tag + 1; p < end; p++) {
        if (*p == '"' || *p == '\'') { /* skip another attribute's value */
            const char* close = memchr(p + 1, *p, (size_t)(end - p - 1));
            if (close == NULL) return NULL;
            p = close;
            continue;
        }
        if ((p[-1] == ' ' || p[-1] == '\t' || p[-1] == '\n' || p[-1] == '\r') && (size_t)(end - p) > len &&
            strncmp(p, name, len) == 0) {
            const char* q = p + len;
            while (q < end && (*q == ' ' || *q == '\t' || *q == '\n' || *q == '\r')) q++;
            if (q >= end || *q != '=') continue;
            q++;
            while (q < end && (*q == ' ' || *q == '\t' || *q == '\n' || *q == '\r')) q++;
            if (q >= end || (*q != '"' && *q != '\'')) return NULL;
            const char* close = memchr(q + 1, *q, (size_t)(end - q - 1));
            return close == NULL ? NULL : xml_text(q + 1, (size_t)(close - q - 1));
        }
    }
    return NULL;
}

/* The end of the start tag beginning at TAG ('>' outside quoted values), or NULL. */
static const char* tag_end(const char* tag)
{
    for (const char* p = tag; *p; p++) {
        if (*p == '"' || *p == '\'') {
            p = strchr(p + 1, *p);
            if (p == NULL) return NULL;
        } else if (*p == '>') {
            return p;
        }
    }
    return NULL;
}

/* The model description of the FMU extracted in DIR; exits with a one-line message if
 * it cannot be read. */
static ModelDescription read_model_description(const char* dir)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/modelDescription.xml", dir);
    char* xml = read_file(path);
    if (xml == NULL) {
        fprintf(stderr, "fmi_host: cannot read %s\n", path);
        exit(1);
    }
    ModelDescription md = {NULL, NULL, 0};
    const char* root = strstr(xml, "<fmiModelDescription");
    const char* root_end = root ? tag_end(root) : NULL;
    md.model_name = root_end ? attribute(root, root_end, "modelName") : NULL;
    int cap = 0;
    for (const char* p = xml; (p = strstr(p, "<ScalarVariable")) != NULL;) {
        const char* end = tag_end(p);
        if (end == NULL) break;
        Variable v = {attribute(p, end, "name"), attribute(p, end, "description"), "", 0};
        char* vr = attribute(p, end, "valueReference");
        /* The type is the first element inside: <Real .../>, <Integer .../>, ... */
        const char* child = end[-1] == '/' ? NULL : strchr(end, '<');
        if (child != NULL) sscanf(child + 1, "%15[A-Za-z]", v.type);
        if (v.name != NULL && vr != NULL) {
            v.vr = (fmi2ValueReference)strtoul(vr, NULL, 10);
            if (md.count == cap) md.variables = realloc(md.variables, sizeof(Variable) * (size_t)(cap = cap ? 2 * cap : 64));
            md.variables[md.count++] = v;
        }
        free(vr);
        p = end;
    }
    free(xml);
    return md;
}

static const Variable* find_variable(const ModelDescription* md, const char* name)
{
    for (int i = 0; i < md->count; i++)
        if (strcmp(md->variables[i].name, name) == 0) return &md->variables[i];
    return NULL;
}

/* The named values of an Integer switch as its description lists them, "0 = name: ...;
 * 1 = name ...": a number, " = " and a name, at the start of the description or after one
 * of ;:,( and blanks (the harness reads them the same way: harness/cosim/fmu.py, _CHOICE).
 * Calls FOUND(code, label, length, context) for each, in the order of the description. */
static void each_choice(const char* description, void (*found)(long, const char*, size_t, void*), void* context)
{
    if (description == NULL) return;
    for (const char* p = description; *p;) {
        const char* q = p;
        if (p != description) {
            if (strchr(";:,(", *p) == NULL) { p++; continue; }
            q = p + 1;
            while (*q && isspace((unsigned char)*q)) q++;
        }
        const char* digits = q + (*q == '-');
        const char* after = digits;
        while (isdigit((unsigned char)*after)) after++;
        if (after > digits && strncmp(after, " = ", 3) == 0 &&
            (isalpha((unsigned char)after[3]) || after[3] == '_')) {
            const char* label = after + 3;
            size_t length = 0;
            while (isalnum((unsigned char)label[length]) || label[length] == '_') length++;
            found(strtol(q, NULL, 10), label, length, context);
            p = label + length;
        } else {
            p++;
        }
    }
}

typedef struct { const char* wanted; long code; int matched; char* listing; size_t used, cap; } ChoiceLookup;

static void match_choice(long code, const char* label, size_t length, void* context)
{
    ChoiceLookup* look = context;
    if (look->wanted != NULL && strlen(look->wanted) == length && strncmp(look->wanted, label, length) == 0) {
        look->code = code; /* a name listed twice takes its last code, as the harness's dict does */
        look->matched = 1;
    }
    char entry[256];
    snprintf(entry, sizeof entry, "%ld = %.*s", code, (int)length, label);
    for (const char* seen = look->listing; seen != NULL && (seen = strstr(seen, entry)) != NULL; seen++)
        if ((seen == look->listing || seen[-1] == ' ') && (seen[strlen(entry)] == ',' || seen[strlen(entry)] == '\0'))
            return; /* listed once already (a description may name a choice twice) */
    size_t need = look->used + strlen(entry) + 3;
    if (need > look->cap) look->listing = realloc(look->listing, look->cap = 2 * need);
    look->used += (size_t)sprintf(look->listing + look->used, "%s%s", look->used ? ", " : "", entry);
}

/* VALUE for variable NAME as the FMU's type: a number, an Integer switch's choice by name,
 * or true/false for a Boolean.  A name the description does not list, or a variable the
 * FMU does not have, ends the master with a one-line message before the FMU is loaded. */
static void resolve(const ModelDescription* md, const char* name, const char* value, char* kind,
                    fmi2ValueReference* vr, double* number)
{
    const char* model = md->model_name ? md->model_name : "the FMU";
    const Variable* v = find_variable(md, name);
    if (v == NULL) {
        fprintf(stderr, "fmi_host: %s has no variable %s (its modelDescription.xml)\n", model, name);
        exit(1);
    }
    *vr = v->vr;
    char* end = NULL;
    double parsed = strtod(value, &end);
    int numeric = end != value && *end == '\0';
    if (strcmp(v->type, "Real") == 0) {
        *kind = 'r';
        if (!numeric) {
            fprintf(stderr, "fmi_host: %s: %s is a Real and cannot take '%s': give a number\n", model, name, value);
            exit(1);
        }
        *number = parsed;
    } else if (strcmp(v->type, "Integer") == 0) {
        *kind = 'i';
        ChoiceLookup look = {value, 0, 0, NULL, 0, 0};
        each_choice(v->description, match_choice, &look);
        if (look.matched) {
            *number = (double)look.code;
        } else if (numeric && parsed == floor(parsed) && parsed >= -2147483648.0 && parsed < 2147483648.0) {
            *number = parsed;
        } else {
            fprintf(stderr, "fmi_host: %s: %s = '%s' is not one of its choices (%s; the FMU's modelDescription.xml)\n",
                    model, name, value, look.used ? look.listing : "it lists none: give a whole number");
            exit(1);
        }
        free(look.listing);
    } else if (strcmp(v->type, "Boolean") == 0) {
        *kind = 'b';
        if (strcmp(value, "true") == 0 || strcmp(value, "1") == 0) *number = 1;
        else if (strcmp(value, "false") == 0 || strcmp(value, "0") == 0) *number = 0;
        else {
            fprintf(stderr, "fmi_host: %s: %s is a Boolean and cannot take '%s': give true or false\n", model, name,
                    value);
            exit(1);
        }
    } else {
        fprintf(stderr, "fmi_host: %s: %s is a %s variable; the master sets Real, Integer and Boolean ones\n", model,
                name, v->type[0] ? v->type : "typeless");
        exit(1);
    }
}

static void print_choice(long code, const char* label, size_t length, void* context)
{
    (void)context;
    printf("%ld %.*s\n", code, (int)length, label);
}

/* ---- choices: the named values of an Integer switch, as `run -p` resolves them ---- */

static int choices(int argc, char** argv)
{
    if (argc < 4) return 2;
    ModelDescription md = read_model_description(argv[2]);
    const Variable* v = find_variable(&md, argv[3]);
    if (v == NULL || strcmp(v->type, "Integer") != 0) {
        fprintf(stderr, "fmi_host: %s is not an Integer variable of %s\n", argv[3], argv[2]);
        return 1;
    }
    each_choice(v->description, print_choice, NULL);
    return 0;
}

/* ---- run ---------------------------------------------------------------------- */

typedef struct { char kind; fmi2ValueReference vr; } Column;

static void print_row(const Fmu* fmu, fmi2Component c, double t, const Column* cols, int n)
{
    printf("%a", t);
    for (int i = 0; i < n; i++) {
        if (cols[i].kind == 'r') {
            double v = 0;
            CHECK(fmu->fmi2GetReal(c, &cols[i].vr, 1, &v) == OK, "get real %u", cols[i].vr);
            printf(" %a", v);
        } else {
            int v = 0;
            int s = cols[i].kind == 'i' ? fmu->fmi2GetInteger(c, &cols[i].vr, 1, &v)
                                        : fmu->fmi2GetBoolean(c, &cols[i].vr, 1, &v);
            CHECK(s == OK, "get %c %u", cols[i].kind, cols[i].vr);
            printf(" %d", v);
        }
    }
    printf("\n");
}

static int close_to(double a, double b) { return fabs(a - b) <= 1e-9 * fmax(fabs(a), fabs(b)); }

static int run(int argc, char** argv)
{
    if (argc < 8) return 2;
    const char *dir = argv[2], *id = argv[3], *guid = argv[4];
    double start = strtod(argv[5], NULL), stop = strtod(argv[6], NULL), h = strtod(argv[7], NULL);
    /* Parameters given by name (-p) are resolved before the FMU is loaded, so a wrong name
     * ends the run before any Python starts. */
    enum { MAX_NAMED = 64 };
    char named_kind[MAX_NAMED];
    fmi2ValueReference named_vr[MAX_NAMED];
    double named_value[MAX_NAMED];
    int nnamed = 0;
    ModelDescription md = {NULL, NULL, 0};
    for (int i = 8; i < argc; i++) {
        if (strcmp(argv[i], "-d") == 0) i += 5;
        else if (strcmp(argv[i], "-p") == 0 && i + 2 < argc) {
            if (md.variables == NULL) md = read_model_description(dir);
            if (nnamed == MAX_NAMED) {
                fprintf(stderr, "fmi_host: more than %d parameters given by name\n", MAX_NAMED);
                return 1;
            }
            resolve(&md, argv[i + 1], argv[i + 2], &named_kind[nnamed], &named_vr[nnamed], &named_value[nnamed]);
            nnamed++;
            i += 2;
        } else if (argv[i][0] == '-') i += 2;
    }
    Fmu fmu;
    load(&fmu, dir, id);
    fmi2Component c = instantiate(&fmu, "run", dir, guid);
    if (c == NULL) { printf("FAIL instantiate returned NULL\n"); return 1; }
    Column cols[64];
    int ncols = 0, drive = 0, named = 0;
    fmi2ValueReference drive_vr[3] = {0, 0, 0};
    double amp = 0, omega = 0;
    for (int i = 8; i < argc; i++) {
        if (strcmp(argv[i], "-o") == 0 && i + 2 < argc && ncols < 64) {
            cols[ncols].kind = argv[i + 1][0];
            cols[ncols++].vr = (fmi2ValueReference)strtoul(argv[i + 2], NULL, 10);
            i += 2;
        } else if (strcmp(argv[i], "-d") == 0 && i + 5 < argc) {
            for (int k = 0; k < 3; k++) drive_vr[k] = (fmi2ValueReference)strtoul(argv[i + 1 + k], NULL, 10);
            amp = strtod(argv[i + 4], NULL);
            omega = strtod(argv[i + 5], NULL);
            drive = 1;
            i += 5;
        } else if (argv[i][0] == '-' && i + 2 < argc) {
            fmi2ValueReference vr = (fmi2ValueReference)strtoul(argv[i + 1], NULL, 10);
            double value = strtod(argv[i + 2], NULL);
            char kind = argv[i][1];
            if (kind == 'p') { /* resolved above, in the same order */
                kind = named_kind[named];
                vr = named_vr[named];
                value = named_value[named++];
            }
            int ivalue = (int)value, s = ERROR;
            if (kind == 'r') s = fmu.fmi2SetReal(c, &vr, 1, &value);
            else if (kind == 'i') s = fmu.fmi2SetInteger(c, &vr, 1, &ivalue);
            else if (kind == 'b') s = fmu.fmi2SetBoolean(c, &vr, 1, &ivalue);
            CHECK(s == OK, "setting %s %s", argv[i + 1], argv[i + 2]);
            i += 2;
        }
    }
    CHECK(fmu.fmi2SetupExperiment(c, 0, 0.0, start, 1, stop) == OK, "setup");
    CHECK(fmu.fmi2EnterInitializationMode(c) == OK, "enter");
    CHECK(fmu.fmi2ExitInitializationMode(c) == OK, "exit");
    double t = start;
    print_row(&fmu, c, t, cols, ncols);
    /* The time arithmetic of fmpy's simulate_fmu, so both masters ask for the same steps. */
    for (long n = 0; !(t > stop || close_to(t, stop)); n++) {
        double next = start + (n + 1) * h;
        if (next > stop && !close_to(next, stop)) next = stop;
        if (drive) {
            double u[3] = {amp * sin(omega * t), amp * omega * cos(omega * t), -amp * omega * omega * sin(omega * t)};
            CHECK(fmu.fmi2SetReal(c, drive_vr, 3, u) == OK, "inputs at %g", t);
        }
        int s = fmu.fmi2DoStep(c, t, next - t, 1);
        CHECK(s == OK, "doStep at %g: %d", t, s);
        if (s != OK) break;
        t = next;
        print_row(&fmu, c, t, cols, ncols);
    }
    CHECK(fmu.fmi2Terminate(c) == OK, "terminate");
    fmu.fmi2FreeInstance(c);
    return failures ? 1 : 0;
}

/* ---- check: what the FMI 2.0 standard requires of a co-simulation FMU ---------- */

static void steps(const Fmu* fmu, fmi2Component c, double* t, int n, double h, fmi2ValueReference vr, double* out)
{
    for (int i = 0; i < n; i++) {
        CHECK(fmu->fmi2DoStep(c, *t, h, 1) == OK, "doStep at %g", *t);
        *t += h;
        CHECK(fmu->fmi2GetReal(c, &vr, 1, &out[i]) == OK, "get after step");
    }
}

static void initialize(const Fmu* fmu, fmi2Component c)
{
    CHECK(fmu->fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) == OK, "setup");
    CHECK(fmu->fmi2EnterInitializationMode(c) == OK, "enter");
    CHECK(fmu->fmi2ExitInitializationMode(c) == OK, "exit");
}

static int check(int argc, char** argv)
{
    if (argc < 8) return 2;
    const char *dir = argv[2], *id = argv[3], *guid = argv[4];
    fmi2ValueReference out = (fmi2ValueReference)strtoul(argv[5], NULL, 10);
    fmi2ValueReference param = (fmi2ValueReference)strtoul(argv[6], NULL, 10);
    double start_value = strtod(argv[7], NULL);
    Fmu fmu;
    load(&fmu, dir, id);  /* every required symbol is exported */
    CHECK(strcmp(fmu.fmi2GetTypesPlatform(), "default") == 0, "types platform %s", fmu.fmi2GetTypesPlatform());
    CHECK(strcmp(fmu.fmi2GetVersion(), "2.0") == 0, "version %s", fmu.fmi2GetVersion());

    fmi2Component c = instantiate(&fmu, "check", dir, guid);
    CHECK(c != NULL, "instantiate");
    if (c == NULL) return 1;
    CHECK(fmu.fmi2SetDebugLogging(c, 1, 0, NULL) == OK, "debug logging on");
    CHECK(fmu.fmi2SetDebugLogging(c, 0, 0, NULL) == OK, "debug logging off");

    /* Start values are readable before initialization. */
    double value = NAN;
    CHECK(fmu.fmi2GetReal(c, &param, 1, &value) == OK && value == start_value, "start value %a, read %a",
          start_value, value);

    /* Bad calls give fmi2Error (with a message), and the instance stays usable. */
    int before = errors_logged;
    CHECK(fmu.fmi2DoStep(c, 0.0, 0.1, 1) == ERROR, "doStep before initialization");
    double bad = NAN;
    CHECK(fmu.fmi2SetReal(c, &param, 1, &bad) == ERROR, "NaN parameter");
    CHECK(fmu.fmi2GetReal(c, &param, 1, &value) == OK && value == start_value, "kept %a", value);
    fmi2ValueReference nowhere = 999999;
    CHECK(fmu.fmi2GetReal(c, &nowhere, 1, &value) == ERROR, "unknown value reference");
    CHECK(fmu.fmi2SetReal(c, &out, 1, &value) == ERROR, "setting an output");
    CHECK(fmu.fmi2GetInteger(c, &param, 1, (int[]){0}) == ERROR, "a Real read as Integer");
    CHECK(fmu.fmi2GetReal(c, &param, 0, NULL) == OK, "nothing to read");
    CHECK(fmu.fmi2DoStep(NULL, 0.0, 0.1, 1) >= ERROR, "NULL instance");
    CHECK(fmu.fmi2GetReal(NULL, &param, 1, &value) >= ERROR, "NULL instance");
    CHECK(errors_logged >= before + 5, "bad calls logged %d errors", errors_logged - before);

    initialize(&fmu, c);
    double t = 0.0, first[10], again[10];
    steps(&fmu, c, &t, 10, 0.5, out, first);
    before = errors_logged;
    CHECK(fmu.fmi2DoStep(c, t, -1.0, 1) == ERROR, "negative step");
    CHECK(fmu.fmi2DoStep(c, t + 7.0, 0.5, 1) == ERROR, "wrong communication point");
    CHECK(errors_logged == before + 2, "each bad step logged an error");
    double last = NAN;
    CHECK(fmu.fmi2GetRealStatus(c, 2 /* fmi2LastSuccessfulTime */, &last) == OK && last == t,
          "last successful time %a, the last step ended at %a", last, t);
    fmi2ValueReference outs[2] = {out, out};
    double pair[2];
    CHECK(fmu.fmi2GetReal(c, outs, 2, pair) == OK && pair[0] == first[9] && pair[1] == first[9], "state kept");

    /* fmi2Reset: back to the instantiated state; the same run gives the same bits. */
    CHECK(fmu.fmi2Reset(c) == OK, "reset");
    CHECK(fmu.fmi2GetReal(c, &param, 1, &value) == OK && value == start_value, "start value after reset");
    initialize(&fmu, c);
    t = 0.0;
    steps(&fmu, c, &t, 10, 0.5, out, again);
    CHECK(memcmp(first, again, sizeof first) == 0, "reset run differs");

    /* FMU state: get, go on, set, go on again; and through serialization. */
    void* state = NULL;
    CHECK(fmu.fmi2GetFMUstate(c, &state) == OK && state != NULL, "get state");
    double t_saved = t, ahead[5], replay[5], revived[5];
    steps(&fmu, c, &t, 5, 0.5, out, ahead);
    CHECK(fmu.fmi2SetFMUstate(c, state) == OK, "set state");
    t = t_saved;
    steps(&fmu, c, &t, 5, 0.5, out, replay);
    CHECK(memcmp(ahead, replay, sizeof ahead) == 0, "restored run differs");
    size_t size = 0;
    CHECK(fmu.fmi2SerializedFMUstateSize(c, state, &size) == OK && size > 0, "serialized size");
    char* bytes = malloc(size);
    CHECK(fmu.fmi2SerializeFMUstate(c, state, bytes, size) == OK, "serialize");
    CHECK(fmu.fmi2FreeFMUstate(c, &state) == OK, "free state");
    void* copy = NULL;
    CHECK(fmu.fmi2DeSerializeFMUstate(c, bytes, size, &copy) == OK && copy != NULL, "deserialize");
    free(bytes);
    fmi2Component other = instantiate(&fmu, "other", dir, guid);  /* a fresh instance takes it too */
    CHECK(other != NULL, "second instance");
    if (other != NULL) {
        void* copy2 = NULL;
        size = 0;
        CHECK(fmu.fmi2SerializedFMUstateSize(c, copy, &size) == OK, "size");
        bytes = malloc(size);
        CHECK(fmu.fmi2SerializeFMUstate(c, copy, bytes, size) == OK, "serialize again");
        CHECK(fmu.fmi2DeSerializeFMUstate(other, bytes, size, &copy2) == OK, "deserialize in other");
        CHECK(fmu.fmi2SetFMUstate(other, copy2) == OK, "set in other");
        double t2 = t_saved;
        steps(&fmu, other, &t2, 5, 0.5, out, revived);
        CHECK(memcmp(ahead, revived, sizeof ahead) == 0, "deserialized run differs");
        CHECK(fmu.fmi2FreeFMUstate(other, &copy2) == OK, "free");
        free(bytes);
        CHECK(fmu.fmi2Terminate(other) == OK, "terminate other");
        fmu.fmi2FreeInstance(other);
    }
    CHECK(fmu.fmi2FreeFMUstate(c, &copy) == OK, "free copy");
    before = errors_logged;
    CHECK(fmu.fmi2SetRealInputDerivatives(c, &param, 1, (int[]){1}, &value) >= ERROR,
          "input derivatives are not offered");
    CHECK(fmu.fmi2Terminate(c) == OK, "terminate");
    fmu.fmi2FreeInstance(c);
    printf("checked %s\n", id);
    return failures ? 1 : 0;
}

/* ---- cycles: memory over many instances -------------------------------------------- */

static long rss_kib(void)
{
    long pages = 0, resident = 0;
    FILE* f = fopen("/proc/self/statm", "r");
    if (f == NULL) return -1;
    if (fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = -1;
    fclose(f);
    return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

static int cycles(int argc, char** argv)
{
    if (argc < 7) return 2;
    const char *dir = argv[2], *id = argv[3], *guid = argv[4];
    int n = atoi(argv[5]);
    fmi2ValueReference out = (fmi2ValueReference)strtoul(argv[6], NULL, 10);
    Fmu fmu;
    load(&fmu, dir, id);
    for (int i = 1; i <= n; i++) {
        fmi2Component c = instantiate(&fmu, "cycle", dir, guid);
        CHECK(c != NULL, "instantiate %d", i);
        if (c == NULL) return 1;
        initialize(&fmu, c);
        double t = 0.0, values[2];
        steps(&fmu, c, &t, 2, 0.25, out, values);
        CHECK(fmu.fmi2Terminate(c) == OK, "terminate");
        fmu.fmi2FreeInstance(c);
        if (i == 1 || i % 20 == 0) printf("rss %d %ld\n", i, rss_kib());
    }
    return failures ? 1 : 0;
}

/* ---- multi: several FMUs and instances in one process, Excitation driving Blocks ---- */

static int multi(int argc, char** argv)
{
    enum { MAX = 8 };
    Fmu fmus[MAX];
    fmi2Component inst[MAX][2];
    fmi2ValueReference plate_vr[MAX][3]; /* plate_z, plate_v, plate_a: Excitation's outputs, Blocks' inputs */
    int n = argc - 2 < MAX ? argc - 2 : MAX, excitation = -1;
    for (int i = 0; i < n; i++) {
        char* spec = strdup(argv[i + 2]);
        char* id = strtok(spec, ":");
        char* dir = strtok(NULL, ":");
        char* guid = strtok(NULL, ":");
        char* plate = strtok(NULL, ":");
        for (int k = 0; k < 3 && plate != NULL; k++) plate_vr[i][k] = (fmi2ValueReference)atoi(plate) + k;
        load(&fmus[i], dir, id);
        if (strcmp(id, "Excitation") == 0) excitation = i;
        for (int k = 0; k < 2; k++) {
            inst[i][k] = instantiate(&fmus[i], k ? "second" : "first", dir, guid);
            CHECK(inst[i][k] != NULL, "instantiate %s", id);
            if (inst[i][k] == NULL) return 1;
            initialize(&fmus[i], inst[i][k]);
        }
    }
    /* The Excitation's outputs feed every Block's plate inputs. */
    double t = 0.0, h = 0.5;
    for (int step = 0; step < 20; step++, t += h) {
        double u[3] = {0, 0, 0};
        if (excitation >= 0) CHECK(fmus[excitation].fmi2GetReal(inst[excitation][0], plate_vr[excitation], 3, u) == OK, "get");
        for (int i = 0; i < n; i++)
            for (int k = 0; k < 2; k++) {
                if (i != excitation) CHECK(fmus[i].fmi2SetReal(inst[i][k], plate_vr[i], 3, u) == OK, "set inputs");
                CHECK(fmus[i].fmi2DoStep(inst[i][k], t, h, 1) == OK, "step %d", i);
            }
    }
    for (int i = 0; i < n; i++)
        for (int k = 0; k < 2; k++) {
            CHECK(fmus[i].fmi2Terminate(inst[i][k]) == OK, "terminate");
            fmus[i].fmi2FreeInstance(inst[i][k]);
        }
    for (int i = 0; i < n; i++) dlclose(fmus[i].handle);
    printf("multi done\n");
    return failures ? 1 : 0;
}

/* ---- bench: the cost of the FMI boundary as a C master sees it ------------------- */

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

#define BENCH_BLOCK 100

static int bench(int argc, char** argv, double started)
{
    if (argc < 8) return 2;
    const char *dir = argv[2], *id = argv[3], *guid = argv[4];
    double h = strtod(argv[5], NULL);
    int n = atoi(argv[6]), nvr = argc - 7;
    fmi2ValueReference vr[64];
    for (int i = 0; i < nvr && i < 64; i++) vr[i] = (fmi2ValueReference)strtoul(argv[7 + i], NULL, 10);
    double values[64];
    Fmu fmu;
    load(&fmu, dir, id);
    fmi2Component c = instantiate(&fmu, "bench", dir, guid);
    if (c == NULL) return 1;
    initialize(&fmu, c);
    CHECK(fmu.fmi2DoStep(c, 0.0, h, 1) == OK, "first step");
    printf("first_step_s %.3f\n", now() - started);
    double t = h, step_time = 0, read_time = 0, block_step = 0, block_read = 0;
    double best_step = INFINITY, best_read = INFINITY;
    for (int k = 1; k <= n; k++, t += h) {
        double t0 = now();
        CHECK(fmu.fmi2DoStep(c, t, h, 1) == OK, "step");
        double t1 = now();
        CHECK(fmu.fmi2GetReal(c, vr, (size_t)nvr, values) == OK, "read");
        double t2 = now();
        block_step += t1 - t0;
        block_read += t2 - t1;
        if (k % BENCH_BLOCK == 0) {
            best_step = fmin(best_step, block_step / BENCH_BLOCK);
            best_read = fmin(best_read, block_read / BENCH_BLOCK);
            step_time += block_step;
            read_time += block_read;
            block_step = block_read = 0;
        }
    }
    step_time += block_step;
    read_time += block_read;
    printf("do_step_us %.2f\nread_us_per_output %.3f\n", 1e6 * step_time / n, 1e6 * read_time / n / nvr);
    printf("do_step_us_quietest %.2f\nread_us_per_output_quietest %.3f\n", 1e6 * best_step, 1e6 * best_read / nvr);
    fmu.fmi2Terminate(c);
    fmu.fmi2FreeInstance(c);
    return failures ? 1 : 0;
}

int main(int argc, char** argv)
{
    double started = now();
    setvbuf(stdout, NULL, _IOLBF, 0);
    int status = 2;
    if (argc > 1 && strcmp(argv[1], "run") == 0) status = run(argc, argv);
    else if (argc > 1 && strcmp(argv[1], "check") == 0) status = check(argc, argv);
    else if (argc > 1 && strcmp(argv[1], "cycles") == 0) status = cycles(argc, argv);
    else if (argc > 1 && strcmp(argv[1], "multi") == 0) status = multi(argc, argv);
    else if (argc > 1 && strcmp(argv[1], "bench") == 0) status = bench(argc, argv, started);
    else if (argc > 1 && strcmp(argv[1], "choices") == 0) status = choices(argc, argv);
    if (status == 2) fprintf(stderr, "usage: see the comment at the top of fmi_host.c\n");
    return status;
}
