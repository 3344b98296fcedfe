/* python_runtime.h - see python_runtime.c. */
#ifndef VIBROBLOCK_PYTHON_RUNTIME_H
#define VIBROBLOCK_PYTHON_RUNTIME_H

#include <stddef.h>

/* Make sure this process has an initialized Python that can import the core's
 * dependencies, loading and starting one if needed.  fmu_root is the FMU's
 * top folder (with modelDescription.xml).  Returns 1 when ready; otherwise 0
 * with a message in `error` saying what is missing and how to fix it. */
int python_runtime_ready(const char* fmu_root, char* error, size_t size);

/* A Python slave's doStep called directly, without pythonfmu's per-call work (see
 * python_runtime.c).  All members NULL: not available, use pythonfmu. */
typedef struct {
    void* slave;      /* the slave object */
    void* do_step;    /* its bound do_step */
    void* log_queue;  /* the list pythonfmu reads its messages from */
    void* native;     /* its Block's record for a doStep without Python, or NULL */
} PythonSlave;

/* A log message of a direct call: status (fmi2Status), category, text. */
typedef void (*PythonSlaveReport)(void* context, int status, const char* category, const char* message);

/* Take the slave pythonfmu has just made on this thread (after its fmi2Instantiate or
 * fmi2Reset returned) for the instance of that name and resource location; returns 1,
 * or 0 with all members NULL. */
int python_slave_claim(PythonSlave* slave, const char* instance_name, const char* resource_location);

/* Release what python_slave_claim took (all members NULL afterwards). */
void python_slave_release(PythonSlave* slave);

/* slave.do_step(t, h): 1 when it returned True, else 0.  Messages the slave logged, and
 * an exception escaping it, are passed to `report` before this returns. */
int python_slave_do_step(const PythonSlave* slave, double t, double h, PythonSlaveReport report, void* context);

/* Advance the slave's block natively from t by h: 1 when done, 0 when the request must go
 * to python_slave_do_step (it then starts from the state this call left). */
int python_slave_native_step(const PythonSlave* slave, double t, double h);

/* Read outputs of the slave's block from its observation, without Python: 1 when every
 * value reference is one the record serves and the values are filled (Integer and Boolean
 * outputs as the doubles their observation slots hold), 0 when the read must go to the
 * slave.  The caller checks the references' types first. */
int python_slave_native_get(const PythonSlave* slave, const unsigned int vr[], size_t nvr, double values[]);

#endif
