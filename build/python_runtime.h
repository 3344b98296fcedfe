/* python_runtime.h - see python_runtime.c. */
#ifndef VIBROBLOCK_PYTHON_RUNTIME_H
#define VIBROBLOCK_PYTHON_RUNTIME_H

#include <stddef.h>

/* Make sure this process has an initialized Python that can import the core's
 * dependencies, loading and starting one if needed.  fmu_root is the FMU's
 * top folder (with modelDescription.xml).  Returns 1 when ready; otherwise 0
 * with a message in `error` saying what is missing and how to fix it. */
int python_runtime_ready(const char* fmu_root, char* error, size_t size);

#endif
