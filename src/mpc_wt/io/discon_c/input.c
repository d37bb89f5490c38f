/* The controller's input file: one entry per line, "key value [value ...]", "#" starts a
 * comment. Read once at the first call; every error names the file, the key and what was
 * expected. */
#include "mpcwt_discon.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void mw_msg(char *msg, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, MW_MSG_LEN, fmt, ap);
    va_end(ap);
}

int mw_finite(double x)
{
    return !isnan(x) && !isinf(x);
}

double mw_interp(double x, const double *xs, const double *ys, int n)
{
    int lo = 0, hi = n - 1;
    if (n == 1 || x <= xs[0]) return ys[0];
    if (x >= xs[n - 1]) return ys[n - 1];
    while (hi - lo > 1) {
        int k = (lo + hi) / 2;
        if (xs[k] <= x)
            lo = k;
        else
            hi = k;
    }
    return (ys[hi] - ys[lo]) / (xs[hi] - xs[lo]) * (x - xs[lo]) + ys[lo];
}

static char *skip_space(char *s)
{
    while (*s && isspace((unsigned char)*s)) s++;
    return s;
}

void mw_input_free(mw_input *in)
{
    free(in->text);
    free(in->key);
    free(in->val);
    free(in->line);
    in->text = NULL;
    in->key = in->val = NULL;
    in->line = NULL;
    in->n = 0;
}

int mw_input_read(mw_input *in, const char *path, char *msg)
{
    FILE *fh;
    long size;
    int i, n_lines = 1;
    char *p;
    memset(in, 0, sizeof(*in));
    snprintf(in->path, sizeof(in->path), "%s", path);
    fh = fopen(path, "rb");
    if (!fh) {
        mw_msg(msg, "mpc-wt controller: cannot open the input file '%s': %s", path,
               strerror(errno));
        return -1;
    }
    if (fseek(fh, 0, SEEK_END) != 0 || (size = ftell(fh)) < 0 || fseek(fh, 0, SEEK_SET) != 0) {
        fclose(fh);
        mw_msg(msg, "mpc-wt controller: cannot read the input file '%s'", path);
        return -1;
    }
    in->text = (char *)malloc((size_t)size + 1);
    if (!in->text) {
        fclose(fh);
        mw_msg(msg, "mpc-wt controller: out of memory reading '%s' (%ld bytes)", path, size);
        return -1;
    }
    if (size > 0 && fread(in->text, 1, (size_t)size, fh) != (size_t)size) {
        fclose(fh);
        mw_input_free(in);
        mw_msg(msg, "mpc-wt controller: cannot read the input file '%s'", path);
        return -1;
    }
    fclose(fh);
    in->text[size] = '\0';
    for (p = in->text; *p; p++)
        if (*p == '\n') n_lines++;
    in->key = (char **)calloc((size_t)n_lines, sizeof(char *));
    in->val = (char **)calloc((size_t)n_lines, sizeof(char *));
    in->line = (int *)calloc((size_t)n_lines, sizeof(int));
    if (!in->key || !in->val || !in->line) {
        mw_input_free(in);
        mw_msg(msg, "mpc-wt controller: out of memory reading '%s'", path);
        return -1;
    }
    p = in->text;
    for (i = 1; p; i++) {
        char *end = strchr(p, '\n'), *hash, *k;
        if (end) *end = '\0';
        hash = strchr(p, '#');
        if (hash) *hash = '\0';
        k = skip_space(p);
        if (*k) {
            char *v = k;
            int j;
            while (*v && !isspace((unsigned char)*v)) v++;
            if (*v) *v++ = '\0';
            for (j = 0; j < in->n; j++) {
                if (strcmp(in->key[j], k) == 0) {
                    mw_msg(msg, "mpc-wt controller: input file '%s': key '%s' is given twice "
                           "(lines %d and %d)", path, k, in->line[j], i);
                    mw_input_free(in);
                    return -1;
                }
            }
            in->key[in->n] = k;
            in->val[in->n] = skip_space(v);
            in->line[in->n] = i;
            in->n++;
        }
        p = end ? end + 1 : NULL;
    }
    return 0;
}

/* the entry of key, or -1 (with msg unless msg is NULL) */
static int find(const mw_input *in, const char *key, char *msg)
{
    int j;
    for (j = 0; j < in->n; j++)
        if (strcmp(in->key[j], key) == 0) return j;
    if (msg) mw_msg(msg, "mpc-wt controller: input file '%s': key '%s' is missing", in->path, key);
    return -1;
}

int mw_has(const mw_input *in, const char *key)
{
    return find(in, key, NULL) >= 0;
}

int mw_count(const mw_input *in, const char *key, char *msg)
{
    int j = find(in, key, msg), n = 0;
    const char *s;
    if (j < 0) return -1;
    s = in->val[j];
    while (*s) {
        while (*s && isspace((unsigned char)*s)) s++;
        if (!*s) break;
        n++;
        while (*s && !isspace((unsigned char)*s)) s++;
    }
    return n;
}

int mw_get_vec(const mw_input *in, const char *key, double *out, int n, char *msg)
{
    int j = find(in, key, msg), i;
    char *s, *end;
    if (j < 0) return -1;
    s = in->val[j];
    for (i = 0; i < n; i++) {
        double v;
        while (*s && isspace((unsigned char)*s)) s++;
        if (!*s) {
            mw_msg(msg, "mpc-wt controller: input file '%s' line %d: key '%s' has %d "
                   "value(s), expected %d", in->path, in->line[j], key, i, n);
            return -1;
        }
        errno = 0;
        v = strtod(s, &end);
        if (end == s || (*end && !isspace((unsigned char)*end)) || !mw_finite(v)) {
            char tok[48];
            int k = 0;
            while (s[k] && !isspace((unsigned char)s[k]) && k < 40) {
                tok[k] = s[k];
                k++;
            }
            tok[k] = '\0';
            mw_msg(msg, "mpc-wt controller: input file '%s' line %d: key '%s' value %d is "
                   "'%s', not a finite number", in->path, in->line[j], key, i + 1, tok);
            return -1;
        }
        out[i] = v;
        s = end;
    }
    while (*s && isspace((unsigned char)*s)) s++;
    if (*s) {
        mw_msg(msg, "mpc-wt controller: input file '%s' line %d: key '%s' has more than the "
               "%d value(s) expected", in->path, in->line[j], key, n);
        return -1;
    }
    return 0;
}

int mw_get(const mw_input *in, const char *key, double *out, char *msg)
{
    return mw_get_vec(in, key, out, 1, msg);
}

int mw_get_int(const mw_input *in, const char *key, int lo, int hi, int *out, char *msg)
{
    double v;
    if (mw_get(in, key, &v, msg)) return -1;
    if (v != floor(v) || v < lo || v > hi) {
        mw_msg(msg, "mpc-wt controller: input file '%s': key '%s' is %g, expected an integer "
               "in [%d, %d]", in->path, key, v, lo, hi);
        return -1;
    }
    *out = (int)v;
    return 0;
}

int mw_get_word(const mw_input *in, const char *key, char *out, size_t n, char *msg)
{
    int j = find(in, key, msg);
    size_t k = 0;
    const char *s;
    if (j < 0) return -1;
    s = in->val[j];
    while (s[k] && !isspace((unsigned char)s[k])) k++;
    if (k == 0 || k >= n) {
        mw_msg(msg, "mpc-wt controller: input file '%s' line %d: key '%s' needs one word "
               "(at most %d characters)", in->path, in->line[j], key, (int)n - 1);
        return -1;
    }
    memcpy(out, s, k);
    out[k] = '\0';
    return 0;
}

static const char *prefixed(const char *prefix, const char *key, char *buf, size_t n)
{
    snprintf(buf, n, "%s%s", prefix, key);
    return buf;
}

int mw_getp(const mw_input *in, const char *prefix, const char *key, double *out, char *msg)
{
    char k[256];
    return mw_get(in, prefixed(prefix, key, k, sizeof(k)), out, msg);
}

int mw_getp_vec(const mw_input *in, const char *prefix, const char *key, double *out, int n,
                char *msg)
{
    char k[256];
    return mw_get_vec(in, prefixed(prefix, key, k, sizeof(k)), out, n, msg);
}

int mw_getp_int(const mw_input *in, const char *prefix, const char *key, int lo, int hi,
                int *out, char *msg)
{
    char k[256];
    return mw_get_int(in, prefixed(prefix, key, k, sizeof(k)), lo, hi, out, msg);
}

double *mw_getp_alloc_n(const mw_input *in, const char *prefix, const char *key, int n,
                        char *msg)
{
    char k[256];
    double *v;
    prefixed(prefix, key, k, sizeof(k));
    v = (double *)malloc((size_t)(n > 0 ? n : 1) * sizeof(double));
    if (!v) {
        mw_msg(msg, "mpc-wt controller: out of memory reading key '%s' (%d values)", k, n);
        return NULL;
    }
    if (mw_get_vec(in, k, v, n, msg)) {
        free(v);
        return NULL;
    }
    return v;
}

double *mw_getp_alloc(const mw_input *in, const char *prefix, const char *key, int *n,
                      char *msg)
{
    char k[256];
    int c = mw_count(in, prefixed(prefix, key, k, sizeof(k)), msg);
    if (c < 0) return NULL;
    if (c == 0) {
        mw_msg(msg, "mpc-wt controller: input file '%s': key '%s' has no values", in->path, k);
        return NULL;
    }
    *n = c;
    return mw_getp_alloc_n(in, prefix, key, c, msg);
}

/* ---- measured signals --------------------------------------------------------------------- */
static const char *const signal_names[MW_SIG_COUNT] = {
    "rotor speed (record 21)", "generator speed (record 20)", "blade 1 pitch (record 4)",
    "blade 2 pitch (record 33)", "blade 3 pitch (record 34)",
    "blade 1 flap moment (record 30)", "blade 2 flap moment (record 31)",
    "blade 3 flap moment (record 32)", "tower-top fore-aft acceleration (record 53)",
    "tower-top side-side acceleration (record 54)"};

int mw_signals_read(const mw_input *in, const char *key, const char *who, int **codes, int *n,
                    char *msg)
{
    double *v;
    int i;
    *codes = NULL;
    v = mw_getp_alloc(in, "", key, n, msg);
    if (!v) return -1;
    *codes = (int *)malloc((size_t)*n * sizeof(int));
    if (!*codes) {
        free(v);
        mw_msg(msg, "mpc-wt %s: out of memory", who);
        return -1;
    }
    for (i = 0; i < *n; i++) {
        if (v[i] != floor(v[i]) || v[i] < 0 || v[i] >= MW_SIG_COUNT) {
            mw_msg(msg, "mpc-wt %s: input file '%s': key '%s' value %d is %g, expected a "
                   "signal code in [0, %d]", who, in->path, key, i + 1, v[i], MW_SIG_COUNT - 1);
            free(v);
            return -1;
        }
        (*codes)[i] = (int)v[i];
    }
    free(v);
    return 0;
}

int mw_signals_get(const mw_meas *m, const int *codes, int n, double *y, const char *who,
                   char *msg)
{
    int i;
    for (i = 0; i < n; i++) {
        double v;
        switch (codes[i]) {
        case MW_SIG_ROTOR_SPEED: v = m->rotor_speed; break;
        case MW_SIG_GEN_SPEED: v = m->gen_speed; break;
        case MW_SIG_PITCH1: v = m->pitch[0]; break;
        case MW_SIG_PITCH2: v = m->pitch[1]; break;
        case MW_SIG_PITCH3: v = m->pitch[2]; break;
        case MW_SIG_FLAP1: v = m->flap[0]; break;
        case MW_SIG_FLAP2: v = m->flap[1]; break;
        case MW_SIG_FLAP3: v = m->flap[2]; break;
        case MW_SIG_TOWER_FA_ACC: v = m->tower_fa_acc; break;
        default: v = m->tower_ss_acc; break;
        }
        if (!mw_finite(v)) {
            mw_msg(msg, "mpc-wt %s: measured %s is not finite at t = %g s", who,
                   signal_names[codes[i]], m->t);
            return -1;
        }
        y[i] = v;
    }
    return 0;
}
