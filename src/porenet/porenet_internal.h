/* porenet_internal.h — helpers shared by the files of src/porenet/. */
#ifndef IBMDEM_PORENET_INTERNAL_H
#define IBMDEM_PORENET_INTERNAL_H
#include <stddef.h>
/* Write the reason into err (vsnprintf) and return -1. */
int pn_fail(char *err, size_t nerr, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
#endif
