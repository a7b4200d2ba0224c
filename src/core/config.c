/* config.c — case-file reader (INI via libinih) checked against a schema.
 *
 * libinih calls our handler for each key; we count lines in our own reader
 * callback so every stored value knows its line, which is what makes the
 * `file:line: section.key: reason` messages possible. */
#include "config.h"

#include <ctype.h>
#include <errno.h>
#include <ini.h>
#include <math.h>
#include <mpi.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#define MAX_SCHEMA_TABLES 64

static const cfg_key_t *schema_tables[MAX_SCHEMA_TABLES];
static int n_schema_tables = 0;

void cfg_schema_add(const cfg_key_t *table)
{
    for (int t = 0; t < n_schema_tables; t++)
        if (schema_tables[t] == table) return;
    if (n_schema_tables == MAX_SCHEMA_TABLES) {
        fprintf(stderr, "internal error: too many schema tables\n");
        abort();
    }
    schema_tables[n_schema_tables++] = table;
}

const cfg_key_t *cfg_schema_at(int i)
{
    for (int t = 0; t < n_schema_tables; t++) {
        for (const cfg_key_t *k = schema_tables[t]; k->section; k++) {
            if (i == 0) return k;
            i--;
        }
    }
    return NULL;
}

const cfg_key_t *cfg_schema_find(const char *section, const char *key)
{
    for (int t = 0; t < n_schema_tables; t++)
        for (const cfg_key_t *k = schema_tables[t]; k->section; k++)
            if (!strcmp(k->section, section) && !strcmp(k->key, key)) return k;
    return NULL;
}

static int schema_has_section(const char *section)
{
    for (int t = 0; t < n_schema_tables; t++)
        for (const cfg_key_t *k = schema_tables[t]; k->section; k++)
            if (!strcmp(k->section, section)) return 1;
    return 0;
}

typedef struct {
    char *section, *key, *value;
    const char *origin; /* "file", "--set" or "default" */
    int line;           /* 0 for --set and defaults */
    int used;
} entry_t;

struct cfg {
    char *path;
    entry_t *e;
    int n, cap;
    int nerr;
    int line;          /* current line while parsing */
    const char *text;  /* string source */
    size_t pos;
    FILE *fp;
};

static cfg_error_hook_t error_hook = NULL;
void cfg_set_error_hook(cfg_error_hook_t hook) { error_hook = hook; }

static int my_rank(void)
{
    int init = 0, r = 0;
    MPI_Initialized(&init);
    if (init) MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
}

static void report(cfg_t *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void report(cfg_t *c, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    c->nerr++;
    if (error_hook) {
        error_hook(msg);
        return;
    }
    if (my_rank() == 0) fprintf(stderr, "%s\n", msg);
}

static entry_t *find(const cfg_t *c, const char *section, const char *key)
{
    /* Last one wins: --set entries are appended after the file's. */
    for (int i = c->n - 1; i >= 0; i--)
        if (!strcmp(c->e[i].section, section) && !strcmp(c->e[i].key, key)) return &c->e[i];
    return NULL;
}

static entry_t *add(cfg_t *c, const char *section, const char *key, const char *value,
                    const char *origin, int line)
{
    if (c->n == c->cap) {
        c->cap = c->cap ? 2 * c->cap : 64;
        c->e = realloc(c->e, (size_t)c->cap * sizeof *c->e);
    }
    entry_t *e = &c->e[c->n++];
    e->section = strdup(section);
    e->key = strdup(key);
    e->value = strdup(value);
    e->origin = origin;
    e->line = line;
    e->used = 0;
    return e;
}

/* ---- conversions ---------------------------------------------------- */

static int parse_double(const char *s, double *v)
{
    char *end;
    errno = 0;
    *v = strtod(s, &end);
    if (end == s || errno == ERANGE) return 0;
    while (isspace((unsigned char)*end)) end++;
    return *end == 0 && isfinite(*v);
}

static int parse_int(const char *s, int *v)
{
    char *end;
    errno = 0;
    long l = strtol(s, &end, 10);
    if (end == s || errno == ERANGE || l > 2147483647L || l < -2147483647L) return 0;
    while (isspace((unsigned char)*end)) end++;
    *v = (int)l;
    return *end == 0;
}

static int parse_bool(const char *s, int *v)
{
    static const char *yes[] = {"true", "yes", "on", "1"}, *no[] = {"false", "no", "off", "0"};
    for (int i = 0; i < 4; i++) {
        if (!strcasecmp(s, yes[i])) { *v = 1; return 1; }
        if (!strcasecmp(s, no[i])) { *v = 0; return 1; }
    }
    return 0;
}

static int parse_vec3(const char *s, double v[3])
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", s);
    for (char *p = buf; *p; p++)
        if (*p == ',') *p = ' ';
    char *p = buf, *end;
    for (int i = 0; i < 3; i++) {
        errno = 0;
        v[i] = strtod(p, &end);
        if (end == p || errno == ERANGE || !isfinite(v[i])) return 0;
        p = end;
    }
    while (isspace((unsigned char)*p)) p++;
    return *p == 0;
}

static int enum_index(const char *choices, const char *s)
{
    int idx = 0;
    const char *p = choices;
    size_t ls = strlen(s);
    while (*p) {
        const char *bar = strchr(p, '|');
        size_t len = bar ? (size_t)(bar - p) : strlen(p);
        if (len == ls && !strncmp(p, s, len)) return idx;
        idx++;
        if (!bar) break;
        p = bar + 1;
    }
    return -1;
}

static const char *type_name(cfg_type_t t)
{
    switch (t) {
    case CFG_DOUBLE: return "a real number";
    case CFG_INT: return "an integer";
    case CFG_BOOL: return "true or false";
    case CFG_STRING: return "a string";
    case CFG_ENUM: return "one of";
    case CFG_VEC3: return "three real numbers";
    }
    return "?";
}

/* Check one value against its schema entry; returns 0 and fills `why` on error. */
static int check_value(const cfg_key_t *k, const char *v, char *why, size_t nwhy)
{
    double d, v3[3];
    int i;
    int ranged = k->min <= k->max;
    switch (k->type) {
    case CFG_DOUBLE:
        if (!parse_double(v, &d)) { snprintf(why, nwhy, "'%s' is not %s", v, type_name(k->type)); return 0; }
        if (ranged && (d < k->min || d > k->max)) {
            snprintf(why, nwhy, "%g is out of range [%g, %g]", d, k->min, k->max);
            return 0;
        }
        return 1;
    case CFG_INT:
        if (!parse_int(v, &i)) { snprintf(why, nwhy, "'%s' is not %s", v, type_name(k->type)); return 0; }
        if (ranged && (i < k->min || i > k->max)) {
            snprintf(why, nwhy, "%d is out of range [%g, %g]", i, k->min, k->max);
            return 0;
        }
        return 1;
    case CFG_BOOL:
        if (!parse_bool(v, &i)) { snprintf(why, nwhy, "'%s' is not %s", v, type_name(k->type)); return 0; }
        return 1;
    case CFG_STRING:
        if (!*v) { snprintf(why, nwhy, "empty value"); return 0; }
        return 1;
    case CFG_ENUM:
        if (enum_index(k->choices, v) < 0) {
            snprintf(why, nwhy, "'%s' is not one of %s", v, k->choices);
            return 0;
        }
        return 1;
    case CFG_VEC3:
        if (!parse_vec3(v, v3)) { snprintf(why, nwhy, "'%s' is not %s", v, type_name(k->type)); return 0; }
        if (ranged)
            for (int j = 0; j < 3; j++)
                if (v3[j] < k->min || v3[j] > k->max) {
                    snprintf(why, nwhy, "component %d = %g is out of range [%g, %g]", j, v3[j], k->min, k->max);
                    return 0;
                }
        return 1;
    }
    return 0;
}

/* ---- parsing ---------------------------------------------------------- */

static int handler(void *user, const char *section, const char *key, const char *value)
{
    cfg_t *c = user;
    char why[512];
    if (!schema_has_section(section)) {
        report(c, "%s:%d: [%s]: unknown section", c->path, c->line, section);
        return 1;
    }
    const cfg_key_t *k = cfg_schema_find(section, key);
    if (!k) {
        report(c, "%s:%d: %s.%s: unknown key", c->path, c->line, section, key);
        return 1;
    }
    entry_t *old = find(c, section, key);
    if (old && old->line > 0) {
        report(c, "%s:%d: %s.%s: given twice (first at line %d)", c->path, c->line, section, key, old->line);
        return 1;
    }
    if (!check_value(k, value, why, sizeof why)) {
        report(c, "%s:%d: %s.%s: %s", c->path, c->line, section, key, why);
        return 1;
    }
    add(c, section, key, value, "file", c->line);
    return 1;
}

static char *reader_file(char *str, int num, void *stream)
{
    cfg_t *c = stream;
    char *r = fgets(str, num, c->fp);
    if (r) c->line++;
    return r;
}

static char *reader_string(char *str, int num, void *stream)
{
    cfg_t *c = stream;
    if (!c->text[c->pos]) return NULL;
    int n = 0;
    while (n < num - 1 && c->text[c->pos]) {
        char ch = c->text[c->pos++];
        str[n++] = ch;
        if (ch == '\n') break;
    }
    str[n] = 0;
    c->line++;
    return str;
}

static cfg_t *finish(cfg_t *c, int rc, int nset, char **sets)
{
    if (rc > 0) report(c, "%s:%d: syntax error (expected [section] or key = value)", c->path, rc);
    for (int s = 0; s < nset; s++) {
        char buf[512], why[512];
        snprintf(buf, sizeof buf, "%s", sets[s]);
        char *eq = strchr(buf, '='), *dot = strchr(buf, '.');
        if (!eq || !dot || dot > eq) {
            report(c, "--set %s: expected section.key=value", sets[s]);
            continue;
        }
        *eq = 0;
        *dot = 0;
        const char *sec = buf, *key = dot + 1, *val = eq + 1;
        const cfg_key_t *k = cfg_schema_find(sec, key);
        if (!k) {
            report(c, "--set %s.%s: unknown key", sec, key);
            continue;
        }
        if (!check_value(k, val, why, sizeof why)) {
            report(c, "--set %s.%s: %s", sec, key, why);
            continue;
        }
        add(c, sec, key, val, "--set", 0);
    }
    if (c->nerr) {
        cfg_free(c);
        return NULL;
    }
    return c;
}

cfg_t *cfg_load(const char *path, int nset, char **sets)
{
    cfg_t *c = calloc(1, sizeof *c);
    c->path = strdup(path);
    c->fp = fopen(path, "r");
    if (!c->fp) {
        report(c, "%s: cannot open: %s", path, strerror(errno));
        cfg_free(c);
        return NULL;
    }
    int rc = ini_parse_stream(reader_file, c, handler, c);
    fclose(c->fp);
    c->fp = NULL;
    return finish(c, rc, nset, sets);
}

cfg_t *cfg_load_string(const char *name, const char *text, int nset, char **sets)
{
    cfg_t *c = calloc(1, sizeof *c);
    c->path = strdup(name);
    c->text = text;
    int rc = ini_parse_stream(reader_string, c, handler, c);
    c->text = NULL;
    return finish(c, rc, nset, sets);
}

void cfg_free(cfg_t *c)
{
    if (!c) return;
    for (int i = 0; i < c->n; i++) {
        free(c->e[i].section);
        free(c->e[i].key);
        free(c->e[i].value);
    }
    free(c->e);
    free(c->path);
    free(c);
}

const char *cfg_path(const cfg_t *c) { return c->path; }

int cfg_has(const cfg_t *c, const char *section, const char *key)
{
    const entry_t *e = find(c, section, key);
    return e && strcmp(e->origin, "default") != 0;
}

int cfg_has_section(const cfg_t *c, const char *section)
{
    for (int i = 0; i < c->n; i++)
        if (!strcmp(c->e[i].section, section) && strcmp(c->e[i].origin, "default")) return 1;
    return 0;
}

/* ---- errors ------------------------------------------------------------ */

void cfg_fail(const cfg_t *c, const char *section, const char *key, const char *fmt, ...)
{
    char reason[768], msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(reason, sizeof reason, fmt, ap);
    va_end(ap);
    const entry_t *e = c ? find(c, section, key) : NULL;
    const char *path = c ? c->path : "(no file)";
    if (e && e->line > 0)
        snprintf(msg, sizeof msg, "%s:%d: %s.%s: %s", path, e->line, section, key, reason);
    else if (e && !strcmp(e->origin, "--set"))
        snprintf(msg, sizeof msg, "--set %s.%s: %s", section, key, reason);
    else
        snprintf(msg, sizeof msg, "%s: %s.%s: %s", path, section, key, reason);
    if (error_hook) {
        error_hook(msg);
        abort(); /* a hook must not return */
    }
    if (my_rank() == 0) fprintf(stderr, "%s\n", msg);
    int init = 0, fin = 0;
    MPI_Initialized(&init);
    MPI_Finalized(&fin);
    if (init && !fin) {
        int size;
        MPI_Comm_size(MPI_COMM_WORLD, &size);
        /* Every rank reads the same input and reaches the same error. */
        MPI_Barrier(MPI_COMM_WORLD);
        MPI_Finalize();
    }
    exit(2);
}

/* ---- getters ------------------------------------------------------------ */

static entry_t *resolve(cfg_t *c, const char *section, const char *key, const cfg_key_t **kp)
{
    const cfg_key_t *k = cfg_schema_find(section, key);
    if (!k) {
        fprintf(stderr, "internal error: %s.%s is not in the schema\n", section, key);
        abort();
    }
    *kp = k;
    entry_t *e = find(c, section, key);
    if (!e) {
        if (!k->def) cfg_fail(c, section, key, "missing key (required: %s)", k->help ? k->help : "");
        e = add(c, section, key, k->def, "default", 0);
    }
    e->used = 1;
    return e;
}

double cfg_double(cfg_t *c, const char *section, const char *key)
{
    const cfg_key_t *k;
    entry_t *e = resolve(c, section, key, &k);
    double v;
    if (k->type != CFG_DOUBLE || !parse_double(e->value, &v)) cfg_fail(c, section, key, "not a real number");
    return v;
}

int cfg_int(cfg_t *c, const char *section, const char *key)
{
    const cfg_key_t *k;
    entry_t *e = resolve(c, section, key, &k);
    int v;
    if (k->type != CFG_INT || !parse_int(e->value, &v)) cfg_fail(c, section, key, "not an integer");
    return v;
}

int cfg_bool(cfg_t *c, const char *section, const char *key)
{
    const cfg_key_t *k;
    entry_t *e = resolve(c, section, key, &k);
    int v;
    if (k->type != CFG_BOOL || !parse_bool(e->value, &v)) cfg_fail(c, section, key, "not a boolean");
    return v;
}

const char *cfg_string(cfg_t *c, const char *section, const char *key)
{
    const cfg_key_t *k;
    entry_t *e = resolve(c, section, key, &k);
    return e->value;
}

int cfg_enum(cfg_t *c, const char *section, const char *key)
{
    const cfg_key_t *k;
    entry_t *e = resolve(c, section, key, &k);
    int i = k->type == CFG_ENUM ? enum_index(k->choices, e->value) : -1;
    if (i < 0) cfg_fail(c, section, key, "'%s' is not one of %s", e->value, k->choices ? k->choices : "");
    return i;
}

void cfg_vec3(cfg_t *c, const char *section, const char *key, double v[3])
{
    const cfg_key_t *k;
    entry_t *e = resolve(c, section, key, &k);
    if (k->type != CFG_VEC3 || !parse_vec3(e->value, v)) cfg_fail(c, section, key, "not three real numbers");
}

/* ---- resolved input ------------------------------------------------------ */

static int cmp_entry(const void *a, const void *b)
{
    const entry_t *x = *(const entry_t *const *)a, *y = *(const entry_t *const *)b;
    int s = strcmp(x->section, y->section);
    return s ? s : strcmp(x->key, y->key);
}

void cfg_write_resolved(const cfg_t *c, FILE *f)
{
    /* Keep the last entry for each key (--set overrides the file). */
    entry_t **list = malloc((size_t)(c->n + 1) * sizeof *list);
    int m = 0;
    for (int i = 0; i < c->n; i++) {
        if (find(c, c->e[i].section, c->e[i].key) != &c->e[i]) continue;
        list[m++] = &c->e[i];
    }
    qsort(list, (size_t)m, sizeof *list, cmp_entry);
    fprintf(f, "; resolved input of %s (every key read, with defaults)\n", c->path);
    const char *sec = "";
    for (int i = 0; i < m; i++) {
        if (strcmp(sec, list[i]->section)) {
            sec = list[i]->section;
            fprintf(f, "\n[%s]\n", sec);
        }
        const char *how = !strcmp(list[i]->origin, "file") ? "" : list[i]->origin;
        if (*how)
            fprintf(f, "%s = %s ; %s\n", list[i]->key, list[i]->value, how);
        else
            fprintf(f, "%s = %s\n", list[i]->key, list[i]->value);
    }
    free(list);
}

/* ---- keys not read ---------------------------------------------------------- */

void cfg_foreach_unused(const cfg_t *c, void (*fn)(const char *section, const char *key, int line, void *ctx), void *ctx)
{
    for (int i = 0; i < c->n; i++) {
        const entry_t *e = &c->e[i];
        /* the entry in force (--set overrides the file), given, and never read */
        if (find(c, e->section, e->key) != e || !strcmp(e->origin, "default") || e->used) continue;
        fn(e->section, e->key, e->line, ctx);
    }
}
