/* config.c — case-file reader (INI) checked against a schema.
 *
 * The reader is our own (lines of any length, strict about what is not a
 * case file: bytes that are not UTF-8 text, indented lines, a '[' without
 * ']'); every stored value knows its line, which is what makes the
 * `file:line: section.key: reason` messages possible. */
#include "config.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <mpi.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

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
    int skip;          /* after a malformed section header: its keys are not read */
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

/* A real number in decimal notation: [+-] digits [. digits] [e [+-] digits]
 * (or .digits); no hexadecimal, inf or nan.  *end past it. */
static int decimal_syntax(const char *s, const char **end)
{
    const char *p = s;
    if (*p == '+' || *p == '-') p++;
    const char *d0 = p;
    while (isdigit((unsigned char)*p)) p++;
    int digits = p > d0;
    if (*p == '.') {
        const char *f0 = ++p;
        while (isdigit((unsigned char)*p)) p++;
        digits |= p > f0;
    }
    if (!digits) return 0;
    if (*p == 'e' || *p == 'E') {
        const char *e = p + 1;
        if (*e == '+' || *e == '-') e++;
        if (!isdigit((unsigned char)*e)) return 0;
        while (isdigit((unsigned char)*e)) e++;
        p = e;
    }
    *end = p;
    return 1;
}

/* One number at s (after blanks); 0 unless decimal and finite as a double. */
static int real_at(const char *s, double *v, const char **end)
{
    while (isspace((unsigned char)*s)) s++;
    if (!decimal_syntax(s, end)) return 0;
    errno = 0;
    *v = strtod(s, NULL);
    if (errno == ERANGE && fabs(*v) > 1.0) return 0; /* overflow; an underflow is 0 or subnormal */
    return isfinite(*v);
}

int cfg_parse_real(const char *s, double *v)
{
    const char *end;
    if (!real_at(s, v, &end)) return 0;
    while (isspace((unsigned char)*end)) end++;
    return *end == 0;
}

static int parse_double(const char *s, double *v) { return cfg_parse_real(s, v); }

static int parse_int(const char *s, int *v)
{
    char *end;
    while (isspace((unsigned char)*s)) s++;
    if (!isdigit((unsigned char)s[*s == '+' || *s == '-'])) return 0;
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

/* Three numbers separated by blanks or commas. */
static int parse_vec3(const char *s, double v[3])
{
    const char *p = s, *end;
    for (int i = 0; i < 3; i++) {
        if (i > 0) {
            while (isspace((unsigned char)*p)) p++;
            if (*p == ',') p++;
        }
        if (!real_at(p, &v[i], &end)) return 0;
        if (*end && !isspace((unsigned char)*end) && *end != ',') return 0;
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

/* The value as quoted in a message: a long one is cut (at a character
 * boundary) and ends with "...". */
static const char *shown(const char *v, char *buf, size_t n)
{
    size_t len = strlen(v);
    if (len < n) return v;
    size_t cut = n - 4;
    while (cut > 0 && ((unsigned char)v[cut] & 0xC0) == 0x80) cut--;
    memcpy(buf, v, cut);
    memcpy(buf + cut, "...", 4);
    return buf;
}

/* Check one value against its schema entry; returns 0 and fills `why` on error. */
/* A hint when strtod would read what the schema refuses (hexadecimal, inf,
 * nan, or a number out of the range of a double). */
static const char *number_hint(const char *v)
{
    char *end;
    for (const char *p = v; *p; p++)
        if (*p == ',') return ""; /* a VEC3: the hint is for single numbers */
    strtod(v, &end);
    while (isspace((unsigned char)*end)) end++;
    return end != v && *end == 0 ? " (decimal notation only, finite, within ±1.8e308: no hexadecimal, inf or nan)"
                                 : "";
}

static int check_value(const cfg_key_t *k, const char *value, char *why, size_t nwhy)
{
    char shortv[96];
    const char *v = shown(value, shortv, sizeof shortv);
    double d, v3[3];
    int i;
    int ranged = k->min <= k->max;
    switch (k->type) {
    case CFG_DOUBLE:
        if (!parse_double(value, &d)) {
            snprintf(why, nwhy, "'%s' is not %s%s", v, type_name(k->type), number_hint(value));
            return 0;
        }
        if (ranged && (d < k->min || d > k->max)) {
            snprintf(why, nwhy, "%g is out of range [%g, %g]", d, k->min, k->max);
            return 0;
        }
        return 1;
    case CFG_INT:
        if (!parse_int(value, &i)) { snprintf(why, nwhy, "'%s' is not %s", v, type_name(k->type)); return 0; }
        if (ranged && (i < k->min || i > k->max)) {
            snprintf(why, nwhy, "%d is out of range [%g, %g]", i, k->min, k->max);
            return 0;
        }
        return 1;
    case CFG_BOOL:
        if (!parse_bool(value, &i)) { snprintf(why, nwhy, "'%s' is not %s", v, type_name(k->type)); return 0; }
        return 1;
    case CFG_STRING:
        if (!*value) { snprintf(why, nwhy, "empty value"); return 0; }
        return 1;
    case CFG_ENUM:
        if (enum_index(k->choices, value) < 0) {
            snprintf(why, nwhy, "'%s' is not one of %s", v, k->choices);
            return 0;
        }
        return 1;
    case CFG_VEC3:
        if (!parse_vec3(value, v3)) { snprintf(why, nwhy, "'%s' is not %s", v, type_name(k->type)); return 0; }
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

static void handle(cfg_t *c, const char *section, const char *key, const char *value)
{
    char why[512];
    if (!schema_has_section(section)) {
        report(c, "%s:%d: [%s]: unknown section", c->path, c->line, section);
        return;
    }
    const cfg_key_t *k = cfg_schema_find(section, key);
    if (!k) {
        report(c, "%s:%d: %s.%s: unknown key", c->path, c->line, section, key);
        return;
    }
    entry_t *old = find(c, section, key);
    if (old && old->line > 0) {
        report(c, "%s:%d: %s.%s: given twice (first at line %d)", c->path, c->line, section, key, old->line);
        return;
    }
    if (!check_value(k, value, why, sizeof why)) {
        report(c, "%s:%d: %s.%s: %s", c->path, c->line, section, key, why);
        return;
    }
    add(c, section, key, value, "file", c->line);
}

size_t cfg_utf8_char(const char *str, size_t n)
{
    const unsigned char *s = (const unsigned char *)str;
    if (n == 0) return 0;
    if (s[0] < 0x80) return 1;
    size_t len;
    unsigned min;
    unsigned cp;
    if ((s[0] & 0xE0) == 0xC0) len = 2, min = 0x80, cp = s[0] & 0x1F;
    else if ((s[0] & 0xF0) == 0xE0) len = 3, min = 0x800, cp = s[0] & 0x0F;
    else if ((s[0] & 0xF8) == 0xF0) len = 4, min = 0x10000, cp = s[0] & 0x07;
    else return 0;
    if (n < len) return 0;
    for (size_t i = 1; i < len; i++) {
        if ((s[i] & 0xC0) != 0x80) return 0;
        cp = (cp << 6) | (s[i] & 0x3F);
    }
    /* overlong forms, UTF-16 surrogates and code points past U+10FFFF are not UTF-8 */
    if (cp < min || (cp >= 0xD800 && cp <= 0xDFFF) || cp > 0x10FFFF) return 0;
    return len;
}

/* Why the n bytes of s are not a line of text (NULL if they are): a NUL byte,
 * a control character other than a tab, or bytes that are not UTF-8.  Column
 * in *col (1-based, in bytes). */
static const char *not_text(const char *s, size_t n, size_t *col, char *why, size_t nwhy)
{
    for (size_t i = 0; i < n;) {
        const unsigned char ch = (unsigned char)s[i];
        *col = i + 1;
        if (ch == 0) return "a NUL byte: this is not a text file";
        if ((ch < 0x20 && ch != '\t') || ch == 0x7F) {
            snprintf(why, nwhy, "control character 0x%02X", ch);
            return why;
        }
        const size_t len = cfg_utf8_char(s + i, n - i);
        if (!len) {
            snprintf(why, nwhy, "byte 0x%02X is not UTF-8 text", ch);
            return why;
        }
        i += len;
    }
    return NULL;
}

static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t') s++;
    char *e = s + strlen(s);
    while (e > s && (e[-1] == ' ' || e[-1] == '\t')) *--e = 0;
    return s;
}

/* One line of the case file (without its newline; a trailing CR is dropped):
 * [section], key = value (or key: value), a comment (; or # first) or blank.
 * A ';' after a blank starts a comment after a value.  `section` holds the
 * current section (the caller's buffer, grown as needed). */
static void parse_line(cfg_t *c, char *line, size_t len, char **section, size_t *seccap)
{
    if (len > 0 && line[len - 1] == '\r') line[--len] = 0;
    if (c->line == 1 && len >= 3 && !memcmp(line, "\xEF\xBB\xBF", 3)) { /* a UTF-8 byte order mark */
        line += 3;
        len -= 3;
    }
    size_t col;
    char whybuf[128];
    const char *bad = not_text(line, len, &col, whybuf, sizeof whybuf);
    if (bad) {
        report(c, "%s:%d: column %zu: %s", c->path, c->line, col, bad);
        return;
    }
    char *s = trim(line);
    if (!*s || *s == ';' || *s == '#') return;
    if (s != line) {
        report(c, "%s:%d: an indented line: keys and [section] headers start at the beginning of the line "
                  "(a value does not continue on the next line)",
               c->path, c->line);
        return;
    }
    if (*s == '[') {
        c->skip = 1;
        char *close = strchr(s, ']');
        if (!close) {
            report(c, "%s:%d: syntax error: '[' without ']' (a section header is [name])", c->path, c->line);
            return;
        }
        *close = 0;
        char *name = trim(s + 1), *rest = trim(close + 1);
        if (*rest && *rest != ';' && *rest != '#') {
            report(c, "%s:%d: syntax error: '%s' after the section header [%s]", c->path, c->line, rest, name);
            return;
        }
        if (!*name) {
            report(c, "%s:%d: syntax error: an empty section name []", c->path, c->line);
            return;
        }
        const size_t ln = strlen(name) + 1;
        if (ln > *seccap) {
            *section = realloc(*section, ln);
            *seccap = ln;
        }
        memcpy(*section, name, ln);
        c->skip = 0;
        return;
    }
    char *sep = s + strcspn(s, "=:");
    if (!*sep) {
        report(c, "%s:%d: syntax error (expected [section] or key = value)", c->path, c->line);
        return;
    }
    const char sepc = *sep;
    if (c->skip) return; /* the header above was reported */
    *sep = 0;
    char *key = trim(s), *value = sep + 1;
    for (char *p = value; *p; p++)
        if (*p == ';' && (p == value || p[-1] == ' ' || p[-1] == '\t')) {
            *p = 0;
            break;
        }
    value = trim(value);
    if (!*key) {
        report(c, "%s:%d: syntax error: no key before '%c'", c->path, c->line, sepc);
        return;
    }
    if (!**section) {
        report(c, "%s:%d: %s: a key before the first [section] header", c->path, c->line, key);
        return;
    }
    handle(c, *section, key, value);
}

/* A case file is text of at most this many bytes (its data files are apart). */
#define CFG_MAX_BYTES (16L << 20)

/* Read the lines of the file (c->fp) or the string (c->text), each of any
 * length, and parse them. */
static void parse(cfg_t *c)
{
    size_t cap = 256, len = 0, seccap = 1;
    char *line = malloc(cap), *section = calloc(1, 1);
    long total = 0;
    int eof = 0;
    c->line = 0;
    while (!eof) {
        len = 0;
        int ch;
        for (;;) {
            ch = c->fp ? getc(c->fp) : (c->text[c->pos] ? (unsigned char)c->text[c->pos++] : EOF);
            if (ch == EOF || ch == '\n') break;
            if (++total > CFG_MAX_BYTES) {
                report(c, "%s:%d: the case file is longer than %ld bytes: not a case file", c->path, c->line + 1,
                       CFG_MAX_BYTES);
                goto done;
            }
            if (ch == 0) break; /* not text: reported by parse_line with the line number */
            if (len + 2 > cap) line = realloc(line, cap *= 2);
            line[len++] = (char)ch;
        }
        if (ch == EOF) {
            eof = 1;
            if (c->fp && ferror(c->fp)) {
                report(c, "%s:%d: cannot read: %s", c->path, c->line + 1, strerror(errno));
                break;
            }
            if (len == 0) break;
        }
        c->line++;
        if (ch == 0) {
            report(c, "%s:%d: column %zu: a NUL byte: this is not a text file", c->path, c->line, len + 1);
            break;
        }
        line[len] = 0;
        parse_line(c, line, len, &section, &seccap);
    }
done:
    free(line);
    free(section);
}

/* A --set value (or --out folder) is one line of UTF-8 text. */
static int set_text_ok(cfg_t *c, const char *sec, const char *key, const char *v)
{
    size_t col;
    char whybuf[128];
    const char *bad = not_text(v, strlen(v), &col, whybuf, sizeof whybuf);
    if (bad) report(c, "--set %s.%s: byte %zu of the value: %s", sec, key, col, bad);
    return bad == NULL;
}

static cfg_t *finish(cfg_t *c, int nset, char **sets)
{
    for (int s = 0; s < nset; s++) {
        char *buf = strdup(sets[s]), why[512];
        char *eq = strchr(buf, '='), *dot = strchr(buf, '.');
        if (!eq || !dot || dot > eq) {
            report(c, "--set %s: expected section.key=value", sets[s]);
            free(buf);
            continue;
        }
        *eq = 0;
        *dot = 0;
        const char *sec = buf, *key = dot + 1, *val = eq + 1;
        const cfg_key_t *k = cfg_schema_find(sec, key);
        if (!k)
            report(c, "--set %s.%s: unknown key", sec, key);
        else if (!set_text_ok(c, sec, key, val))
            ;
        else if (!check_value(k, val, why, sizeof why))
            report(c, "--set %s.%s: %s", sec, key, why);
        else
            add(c, sec, key, val, "--set", 0);
        free(buf);
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
    struct stat st;
    const char *why = !c->fp ? strerror(errno)
                      : fstat(fileno(c->fp), &st) == 0 && S_ISDIR(st.st_mode) ? strerror(EISDIR)
                                                                                : NULL;
    if (why) {
        report(c, "%s: cannot open: %s", path, why);
        if (c->fp) fclose(c->fp);
        cfg_free(c);
        return NULL;
    }
    parse(c);
    fclose(c->fp);
    c->fp = NULL;
    return finish(c, nset, sets);
}

cfg_t *cfg_load_string(const char *name, const char *text, int nset, char **sets)
{
    cfg_t *c = calloc(1, sizeof *c);
    c->path = strdup(name);
    c->text = text;
    parse(c);
    c->text = NULL;
    return finish(c, nset, sets);
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
