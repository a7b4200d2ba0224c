/* modules.h — the registry of every module's case-file keys.  A new module
 * adds its register function to modules_register_keys() (src/core/modules.c). */
#ifndef IBMDEM_MODULES_H
#define IBMDEM_MODULES_H
void modules_register_keys(void);
#endif
