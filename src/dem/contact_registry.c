/* contact_registry.c — the contact laws known to [contact] law.  A new law:
 * a new file contact_<name>.c defining a dem_contact_law_t, one line in
 * the table below and its name in dem_contact_law_choices (same order). */
#include <string.h>

#include "dem_private.h"

extern const dem_contact_law_t dem_contact_linear;
extern const dem_contact_law_t dem_contact_hertz_mindlin;

static const dem_contact_law_t *const laws[] = {
    &dem_contact_linear,
    &dem_contact_hertz_mindlin,
};

const char dem_contact_law_choices[] = "linear|hertz_mindlin";

const dem_contact_law_t *dem_contact_law_find(const char *name)
{
    for (size_t i = 0; i < sizeof laws / sizeof laws[0]; i++)
        if (!strcmp(laws[i]->name, name)) return laws[i];
    return NULL;
}
