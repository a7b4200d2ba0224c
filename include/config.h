/* config.h — case-file reader with a schema of every key.
 *
 * A case file is an INI file ([section] then key = value, comments after ;
 * or #), UTF-8 text with lines of any length.  Every key that a
 * module understands is declared once in a schema table (cfg_key_t) with its
 * type, default, range and help text; the schema is what `ibmdem check`
 * prints and what docs/user-guide.md lists.  Unknown keys, wrong types and
 * out-of-range values are reported as `file:line: section.key: reason`
 * before anything runs.  Modules read their values with the typed getters,
 * which apply the default when a key is absent, or stop with "missing key"
 * when the schema gives no default.
 */
#ifndef IBMDEM_CONFIG_H
#define IBMDEM_CONFIG_H

#include <stdio.h>

typedef enum { CFG_DOUBLE, CFG_INT, CFG_BOOL, CFG_STRING, CFG_ENUM, CFG_VEC3 } cfg_type_t;

/* A key without a default (def NULL): required whenever its module is part of
 * the scene, optional (absent: not used, or a default the help states), or
 * needed in some configurations only (the help says which). */
typedef enum { CFG_REQUIRED = 0, CFG_OPTIONAL = 1, CFG_CONDITIONAL = 2 } cfg_need_t;

typedef struct {
    const char *section;
    const char *key;
    cfg_type_t type;
    const char *def;     /* default as text; NULL: required when the module is active */
    double min, max;     /* inclusive numeric range (each component for VEC3); unused if min > max */
    const char *choices; /* CFG_ENUM: "a|b|c" */
    const char *help;    /* one line */
    cfg_need_t need;     /* def NULL: required, optional or conditional (the keys table says which) */
} cfg_key_t;

/* Sentinel-terminated tables: the last entry has section == NULL. */
void cfg_schema_add(const cfg_key_t *table);
const cfg_key_t *cfg_schema_find(const char *section, const char *key);
/* Iterate the schema: returns NULL past the end. */
const cfg_key_t *cfg_schema_at(int i);

typedef struct cfg cfg_t;

/* Parse a case file and the --set overrides ("section.key=value").  On any
 * error (I/O, syntax, unknown key, bad type or range) the messages are
 * printed to stderr and NULL is returned.  The schema must be complete
 * before this is called. */
cfg_t *cfg_load(const char *path, int nset, char **sets);
/* Parse from a string (tests); `name` is used as the file name in messages. */
cfg_t *cfg_load_string(const char *name, const char *text, int nset, char **sets);
void cfg_free(cfg_t *c);

const char *cfg_path(const cfg_t *c);
int cfg_has(const cfg_t *c, const char *section, const char *key);
int cfg_has_section(const cfg_t *c, const char *section);

/* Typed getters.  They stop the program (cfg_fail) on a missing required key. */
double cfg_double(cfg_t *c, const char *section, const char *key);
int cfg_int(cfg_t *c, const char *section, const char *key);
int cfg_bool(cfg_t *c, const char *section, const char *key);
const char *cfg_string(cfg_t *c, const char *section, const char *key);
int cfg_enum(cfg_t *c, const char *section, const char *key); /* index in choices */
void cfg_vec3(cfg_t *c, const char *section, const char *key, double v[3]);

/* Stop with "file:line: section.key: reason" (line of the key if it was
 * given, of the file otherwise).  Collective-safe: every rank parses the same
 * file, so every rank reaches the same error; only rank 0 prints. */
void cfg_fail(const cfg_t *c, const char *section, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 4, 5), noreturn));

/* A real number as the case file writes it: decimal notation with an
 * optional exponent (1, -2.5, 3e-4), finite; no hexadecimal, inf or nan.
 * Leading and trailing blanks are allowed.  Returns 1 and sets *v if s is one. */
int cfg_parse_real(const char *s, double *v);
/* Bytes of the valid UTF-8 character at s (n bytes available), 0 if the
 * bytes there are not UTF-8 (overlong forms and surrogates included). */
size_t cfg_utf8_char(const char *s, size_t n);

/* Error handling mode: by default cfg_fail exits with status 2.  Tests can
 * install a hook (e.g. a longjmp) that is called with the message instead. */
typedef void (*cfg_error_hook_t)(const char *msg);
void cfg_set_error_hook(cfg_error_hook_t hook);

/* Call fn for every key given (file or --set) that no getter has read, in
 * the order given (line 0: --set).  A run notes them in its log: keys of a
 * model the scene does not use. */
void cfg_foreach_unused(const cfg_t *c, void (*fn)(const char *section, const char *key, int line, void *ctx),
                        void *ctx);

/* Write every key that was read (with its resolved value and whether it came
 * from the file, --set or the default) and every given key, as an INI file. */
void cfg_write_resolved(const cfg_t *c, FILE *f);

#endif
