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
/* the most lidar measurements a law reads: InflowWind v5.0.0 gives at most 5 beams (single
 * points) or 5 pulse gates */
#define MW_LIDAR_MAX 5

typedef struct {
    double t;              /* record 2 [s] */
    double dt;             /* record 3, the communication interval [s] */
    double pitch[3];       /* records 4, 33, 34 [rad] */
    double gen_speed;      /* record 20 [rad/s] */
    double rotor_speed;    /* record 21 [rad/s] */
    double gen_torque;     /* record 23 [N m] */
    double flap[3];        /* records 30-32, blade root out-of-plane moments [N m] */
    double tower_fa_acc;   /* record 53 [m/s^2] */
    double tower_ss_acc;   /* record 54 [m/s^2] */
    double azimuth;        /* record 60 [rad] */
    double gen_power;      /* record 15 [W] */
    /* OpenFAST's lidar block (records 2001-2500, InflowWind's lidar through ServoDyn's
     * extended swap array): sensor type, beams, pulse gates, then n = beams x gates speeds and
     * the n measurement points' x, then y, then z */
    int lidar_type, lidar_beams, lidar_gates, lidar_n;
    double lidar_speed[MW_LIDAR_MAX];   /* records 2005 .. 2004 + n [m/s] */
    double lidar_y[MW_LIDAR_MAX], lidar_z[MW_LIDAR_MAX];   /* the points' y and z [m] */
} mw_meas;

/* each blade's wind from the lidar records (see discon.c) and when it was measured [s]; -1 with a message naming the
 * records on a configuration no law reads or a speed that is not finite */
int mw_lidar_winds(const mw_meas *m, double cos_cone, double lead_s, double u[3],
                   double *taken, const char *who, char *msg);

/* logging channels a kind returns beside its demands (Bladed's records 65 and L1 = record 63
 * on): each kind lists its own, in order, in its export (LawExport.log) */
#define MW_LOG_MAX 12

typedef struct {
    double pitch[3];       /* demands [rad] */
    double torque;         /* demand [N m] */
    int nlog;              /* logging channels this step (0 to MW_LOG_MAX) */
    double log[MW_LOG_MAX];
} mw_cmd;

/* measured signals an estimator reads, by code (the input file's lists of codes) */
enum { MW_SIG_ROTOR_SPEED, MW_SIG_GEN_SPEED, MW_SIG_PITCH1, MW_SIG_PITCH2, MW_SIG_PITCH3,
       MW_SIG_FLAP1, MW_SIG_FLAP2, MW_SIG_FLAP3, MW_SIG_TOWER_FA_ACC, MW_SIG_TOWER_SS_ACC,
       MW_SIG_COUNT };
/* read the codes of key (allocated into *codes, *n of them); -1 with msg on a bad code */
int mw_signals_read(const mw_input *in, const char *key, const char *who, int **codes, int *n,
                    char *msg);
/* the signals' values at this step into y; -1 with msg (naming the record) if one is not
 * finite */
int mw_signals_get(const mw_meas *m, const int *codes, int n, double *y, const char *who,
                   char *msg);

/* a controller: its step and how to free it */
typedef struct mw_ctrl mw_ctrl;
struct mw_ctrl {
    double dt;                                     /* the period it was designed for [s] */
    int (*step)(mw_ctrl *self, const mw_meas *m, mw_cmd *out, char *msg);
    void (*destroy)(mw_ctrl *self);
};

/* the laws: each law's C file defines mw_<law>_new, which reads the input file and makes its
 * controller (NULL with msg on failure); the library holds the laws mw_laws.h lists (written
 * by the export: MW_LAWS(X) expands X(law) for each), discon.c makes the one the input file's
 * `kind` names */
#include "mw_laws.h"
#define MW_LAW_NEW(law) mw_ctrl *mw_##law##_new(const mw_input *in, char *msg);
MW_LAWS(MW_LAW_NEW)
#undef MW_LAW_NEW

/* ---- shared parts --------------------------------------------------------------------- */
/* input keys are "<prefix><name>"; these read one with the prefix */
int mw_getp(const mw_input *in, const char *prefix, const char *key, double *out, char *msg);
int mw_getp_vec(const mw_input *in, const char *prefix, const char *key, double *out, int n,
                char *msg);
int mw_getp_int(const mw_input *in, const char *prefix, const char *key, int lo, int hi,
                int *out, char *msg);
/* a vector of any length, allocated (NULL with msg on failure); n receives its length */
double *mw_getp_alloc(const mw_input *in, const char *prefix, const char *key, int *n,
                      char *msg);
/* the same with exactly n values */
double *mw_getp_alloc_n(const mw_input *in, const char *prefix, const char *key, int n,
                        char *msg);

/* the baseline's torque law and PI data (Jonkman's law, regions 1.5, 2, 2.5, 3) */
#define MW_MIN_PITCH_MAX 64
typedef struct {
    double a, w_set, kp, ki, theta_k, dt, p_min, p_max, rate, tq_rate, tq_max;
    double w_cutin, w_rgn2, w_trans, w_rated, w_sync, slope15, slope25, k_opt, tq_cap;
    double p_rated, eta, tq_rated, rgn3_pitch;
    int constant_power;
    /* the minimum-pitch schedule: filtered generator speeds and pitch above p_min */
    int mp_n;
    double mp_w[MW_MIN_PITCH_MAX], mp_off[MW_MIN_PITCH_MAX];
} mw_law;
int mw_law_read(const mw_input *in, const char *prefix, mw_law *law, char *msg);
double mw_law_torque(const mw_law *law, double w, double pitch, double p3);
/* the minimum-pitch schedule's pitch above p_min at filtered generator speed w [rad] */
double mw_law_min_pitch_offset(const mw_law *law, double w);

/* the baseline's torque schedule as another controller's generator torque: the generator
 * speed low-passed at the law's corner, the pitch counted from the below-rated offset under
 * region 2 and from the minimum-pitch schedule above, the torque within limits (input keys
 * "law.*" and "law_torque") */
typedef struct {
    mw_law law;
    double a, offset, lo, hi, w;
    int started;
} mw_torque_law;
int mw_torque_law_read(const mw_input *in, mw_torque_law *t, char *msg);
double mw_torque_law_step(mw_torque_law *t, double gen_speed, double pitch, double power);
/* the law's minimum pitch at its filtered speed: fine pitch plus the minimum-pitch schedule's
 * offset [rad] (a law that has not stepped yet: -inf, no floor) */
double mw_torque_law_min_pitch(const mw_torque_law *t);

/* second-order sections in transposed direct form II on nch signals, started at the steady
 * state of their first input (scipy's sosfilt_zi) (ibc.c) */
typedef struct {
    int n, nch, started;
    double *sos, *zi1, *zi;       /* n x 6; n x 2 per unit input; n x 2 x nch */
} mw_sos;
/* the sections from `key` (6 values each) and their unit-input state from `zkey`; -1 with msg */
int mw_sos_read(const mw_input *in, const char *who, const char *key, const char *zkey,
                int nch, mw_sos *f, char *msg);
/* one sample of each of the nch signals */
void mw_sos_step(mw_sos *f, const double *x, double *y);
void mw_sos_free(mw_sos *f);

/* what IBC and Coleman IPC share (ibc.c): the fade-in's power fractions, the power it refers
 * to, the power low-pass's pole and state, and the limits on the summed command */
typedef struct {
    int has_p;
    double w_lo, w_hi, rated, p_alpha, pmin, pmax, rate, p_filt;
} mw_addon;

/* individual blade control added to a collective command (ibc.c) */
typedef struct {
    int on, ng, remove_mean, has_last;
    double *gp, *gg;
    mw_sos hp, bs;
    mw_addon a;
    double amp, last[3];
    double weight, gain, u[3];    /* this step's fade-in weight, gain and blade additions */
} mw_ibc;
int mw_ibc_read(const mw_input *in, mw_ibc *b, char *msg);
void mw_ibc_free(mw_ibc *b);
/* the blades' pitch demands from the collective ones pc; -1 with msg on a non-finite input */
int mw_ibc_step(mw_ibc *b, const mw_meas *m, double dt, const double *pc, double *out,
                char *msg);
/* Coleman-frame integral IPC added to a collective command (ibc.c): the blades' root moments
 * to tilt and yaw, rotated by the scheduled azimuth offset, integrated with the scheduled gain
 * (amplitude clamped), faded in with the low-passed power, back to the blades; the
 * collective's part within the pitch rate first, the cyclic within what is left */
typedef struct {
    int on, ng, has_last;
    double *gp, *gk, *gphi;
    mw_addon a;
    double amp;
    double th_c, th_s, c_last, a_last[3];
    double weight, tilt, yaw, cyc_c, cyc_s;   /* this step's weight, moments, cyclic pitch */
} mw_cipc;
int mw_cipc_read(const mw_input *in, mw_cipc *b, char *msg);
void mw_cipc_free(mw_cipc *b);
int mw_cipc_step(mw_cipc *b, const mw_meas *m, double dt, const double *pc, double *out,
                 char *msg);
/* whether the input file has a key */
int mw_has(const mw_input *in, const char *key);

/* a controller of `size` bytes (its mw_ctrl first) read by `read`; NULL with msg on failure
 * (then `destroy` has freed what `read` allocated) */
mw_ctrl *mw_ctrl_new(size_t size, const char *who,
                     int (*step)(mw_ctrl *, const mw_meas *, mw_cmd *, char *),
                     void (*destroy)(mw_ctrl *),
                     int (*read)(const mw_input *, mw_ctrl *, char *), const mw_input *in,
                     char *msg);

/* the rotor-effective wind speed's extended Kalman filter (rotor speed, pitch, torque) */
typedef struct {
    double *tx, *ty, *c;
    int ntx, nty, kx, ky;
    double radius, rho, gear, inertia, dt, q0, q1, r, vmin, vmax, tsr0, tsr1;
    double p0_speed, p0_wind;
    double start_gain, start_rated, start_speed;   /* the first torque where none is measured */
    double x[2], p[4], u[2];
    int started;
} mw_windest;
int mw_windest_read(const mw_input *in, const char *prefix, mw_windest *e, char *msg);
void mw_windest_free(mw_windest *e);
void mw_windest_reset(mw_windest *e);
double mw_windest_step(mw_windest *e, double rotor_speed, double pitch, double gen_torque);
int mw_windest_outside(const mw_windest *e);

/* which design of a wind-scheduled controller acts */
typedef struct {
    double *grid, *mid;
    int n;
    double dt, tau, hyst;
    double wind, measured, floored;
    int active, started;
    int from_estimator;    /* this step's scheduling wind came from the estimator */
    mw_windest est;
    /* the region floor: the trim's pitch curve above rated (winds, pitches), the pitch above
       which it counts [rad] while the rotor runs above floor_pitch_speed [rad/s], the rotor
       speed above which the design wind is at least floor_wind3 [rad/s, m/s] */
    int has_floor, n_floor;
    double *floor_w, *floor_p, floor_pitch, floor_pitch_speed, floor_speed, floor_wind3;
} mw_schedule;
int mw_schedule_read(const mw_input *in, const char *prefix, double dt, mw_schedule *s,
                     char *msg);
void mw_schedule_free(mw_schedule *s);
/* 1 when the low-passed wind lies more than 1 m/s beyond the grid's ends */
int mw_schedule_outside(const mw_schedule *s);
/* 1 when this step's wind came from the estimator and its estimate left its validity */
int mw_schedule_estimator_outside(const mw_schedule *s);
void mw_schedule_reset(mw_schedule *s);
/* this step's active index; *switched = 1 on a switch */
int mw_schedule_update(mw_schedule *s, const mw_meas *m, int *switched);
/* the same with a wind measured otherwise (the LIDAR's rotor mean); m for the region floor */
int mw_schedule_update_wind(mw_schedule *s, double wind, const mw_meas *m, int *switched);

/* a steady-state Kalman filter on a linear model with the winds as random walks */
typedef struct {
    int n, ny, nu;
    double *a, *b, *c, *d, *gain, *y0, *xa, *work;
    int started;
} mw_kalman;
int mw_kalman_read(const mw_input *in, const char *prefix, int nu, mw_kalman *k, char *msg);
void mw_kalman_free(mw_kalman *k);
void mw_kalman_reset(mw_kalman *k);
/* predict with u (deviation) and correct with y (absolute); -1 on a non-finite y */
int mw_kalman_update(mw_kalman *k, const double *y, const double *u);

/* helpers */
void mw_msg(char *msg, const char *fmt, ...);
int mw_finite(double x);
/* numpy's interp: linear between the points (xs increasing), held beyond the ends */
double mw_interp(double x, const double *xs, const double *ys, int n);

#endif
