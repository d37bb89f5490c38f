/* mpc-wt controllers as a Bladed-style controller library (DISCON).
 *
 * The library reads everything it needs from its input file (accINFILE) at the first call:
 * which controller it is and every number of its design. It keeps one instance per
 * simulation root name (avcOUTNAME), so two turbines that load one copy of the library do
 * not share state. Memory is allocated at the first call and freed at the last; a step
 * allocates nothing.
 */
#ifndef MPCWT_DISCON_H
#define MPCWT_DISCON_H

#include <stddef.h>

#define MW_MSG_LEN 1024

/* ---- the input file ------------------------------------------------------------------ */
typedef struct {
    char path[1024];      /* as given, for messages */
    char *text;           /* the whole file, NUL-separated lines */
    int n_lines;
    char **key;           /* per entry: its key */
    char **val;           /* per entry: the rest of the line (values) */
    int *line;            /* per entry: its line number */
    int n;                /* entries */
} mw_input;

int mw_input_read(mw_input *in, const char *path, char *msg);
void mw_input_free(mw_input *in);
/* a scalar; 0 on success, else -1 with msg naming the file and the key */
int mw_get(const mw_input *in, const char *key, double *out, char *msg);
/* exactly n values */
int mw_get_vec(const mw_input *in, const char *key, double *out, int n, char *msg);
/* the number of values of a key (-1 with msg if missing) */
int mw_count(const mw_input *in, const char *key, char *msg);
/* a word (no spaces) */
int mw_get_word(const mw_input *in, const char *key, char *out, size_t n, char *msg);
/* an integer within [lo, hi] */
int mw_get_int(const mw_input *in, const char *key, int lo, int hi, int *out, char *msg);

/* ---- what a controller sees at a step ------------------------------------------------ */
typedef struct {
    double t;              /* record 2 [s] */
    double pitch[3];       /* records 4, 33, 34 [rad] */
    double gen_speed;      /* record 20 [rad/s] */
    double rotor_speed;    /* record 21 [rad/s] */
    double gen_torque;     /* record 23 [N m] */
    double flap[3];        /* records 30-32, blade root out-of-plane moments [N m] */
    double tower_fa_acc;   /* record 53 [m/s^2] */
    double tower_ss_acc;   /* record 54 [m/s^2] */
    double azimuth;        /* record 60 [rad] */
    double gen_power;      /* record 15 [W] */
} mw_meas;

typedef struct {
    double pitch[3];       /* demands [rad] */
    double torque;         /* demand [N m] */
} mw_cmd;

/* a controller: its step and how to free it */
typedef struct mw_ctrl mw_ctrl;
struct mw_ctrl {
    double dt;                                     /* the period it was designed for [s] */
    int (*step)(mw_ctrl *self, const mw_meas *m, mw_cmd *out, char *msg);
    void (*destroy)(mw_ctrl *self);
};

/* the kinds */
mw_ctrl *mw_baseline_new(const mw_input *in, char *msg);

/* helpers */
void mw_msg(char *msg, const char *fmt, ...);
int mw_finite(double x);

#endif
