/* Do et al.'s LQR full-state feedback on the estimates of a proportional-integral observer
 * (Do et al. 2020, eqs 11-16 and Fig. 2), scheduled over the rotor-effective wind.
 *
 * One design per grid wind. Each holds its observer, discretized with a zero-order hold at the
 * controller's period, over the states and the unknown inputs (the blade-effective wind
 * deviations), x_e = [x; f]:
 *     x_e <- A_d x_e + B_d [u - u0; y - y0],
 * and the command of the LQR with the unknown-input feedforward,
 *     u = u0 - [K K_f] x_e   (the pitch inputs),
 * clipped to the pitch limits and to what a first-order actuator can follow from the measured
 * pitch. The generator torque is the baseline's schedule on the low-passed generator speed (in
 * region III capped at the design's torque), or K_opt Omega_g^2, or the design's torque.
 *
 * The schedule (windest.c) picks the design; on a switch the new one continues from the old
 * one's estimate and last command in absolute units (bumpless), and the torque law keeps its
 * filtered speed. */
#include "mpcwt_discon.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    int nx, nf, ny, nu, ng, region, has_law;
    double *ad, *bd, *gain, *y0, *u0, *x0d0;
    int *gi;
    double k_opt, pitch_floor;
    /* state */
    double *xe, *udev;
} mw_lqr_point;

typedef struct {
    mw_ctrl base;
    int n, *signals, n_signals, has_law;
    double dt, limits[5];
    double *y, *work, u[4];
    mw_lqr_point *pt;
    mw_schedule sched;
    mw_torque_law law;
} mw_lqr;

static double dmin(double a, double b) { return a < b ? a : b; }
static double dmax(double a, double b) { return a > b ? a : b; }

static void point_reset(mw_lqr_point *p)
{
    memset(p->xe, 0, (size_t)(p->nx + p->nf) * sizeof(double));
    memset(p->udev, 0, (size_t)p->nu * sizeof(double));
}

/* continue from another design's estimate and last command, in absolute units */
static void hand_over(mw_lqr_point *to, const mw_lqr_point *from)
{
    int i;
    for (i = 0; i < to->nx + to->nf; i++)
        to->xe[i] = from->xe[i] + (from->x0d0[i] - to->x0d0[i]);
    for (i = 0; i < to->nu; i++) to->udev[i] = from->udev[i] + from->u0[i] - to->u0[i];
}

static int lqr_step(mw_ctrl *self, const mw_meas *m, mw_cmd *out, char *msg)
{
    mw_lqr *c = (mw_lqr *)self;
    int switched, k, i, j, b, n, before = c->sched.active;
    mw_lqr_point *p;
    double *xn = c->work, pitch[3], torque, lo, reach = c->limits[4];
    if (!mw_finite(m->rotor_speed) || !mw_finite(m->gen_torque)
        || !mw_finite(m->pitch[0] + m->pitch[1] + m->pitch[2]) || !mw_finite(m->gen_speed)) {
        mw_msg(msg, "mpc-wt lqr-pio: measured rotor speed (record 21), generator speed (20), "
               "torque (23) or pitch (4, 33, 34) is not finite at t = %g s", m->t);
        return -1;
    }
    if (mw_signals_get(m, c->signals, c->n_signals, c->y, "lqr-pio", msg)) return -1;
    k = mw_schedule_update(&c->sched, m, &switched);
    p = &c->pt[k];
    if (switched) {
        point_reset(p);
        hand_over(p, &c->pt[before]);
        if (!(p->has_law && c->pt[before].has_law)) c->law.started = 0;
    }
    /* the observer over the last period */
    n = p->nx + p->nf;
    for (i = 0; i < n; i++) {
        const double *row = p->bd + (size_t)i * (p->nu + p->ny);
        double acc = 0.0;
        for (j = 0; j < n; j++) acc += p->ad[(size_t)i * n + j] * p->xe[j];
        for (j = 0; j < p->nu; j++) acc += row[j] * p->udev[j];
        for (j = 0; j < p->ny; j++) acc += row[p->nu + j] * (c->y[j] - p->y0[j]);
        xn[i] = acc;
    }
    memcpy(p->xe, xn, (size_t)n * sizeof(double));
    /* the LQR's command with the feedforward, within the limits */
    for (i = 0; i < 4; i++) c->u[i] = p->u0[i];
    for (i = 0; i < p->ng; i++) {
        double acc = 0.0;
        for (j = 0; j < n; j++) acc += p->gain[(size_t)i * n + j] * p->xe[j];
        c->u[p->gi[i]] -= acc;
    }
    /* the lowest pitch: the baseline's minimum-pitch schedule on the law's filtered speed
     * (continuous, as the baseline's and the TS law's), else the design's floor */
    lo = dmax(c->limits[0], p->has_law && c->law.started ? mw_torque_law_min_pitch(&c->law)
                                                          : p->pitch_floor);
    for (b = 0; b < 3; b++) {
        pitch[b] = dmin(dmax(c->u[b], lo), c->limits[1]);
        if (reach >= 0.0)
            pitch[b] = dmin(dmax(pitch[b], m->pitch[b] - reach), m->pitch[b] + reach);
    }
    if (p->has_law) {
        double mean = (pitch[0] + pitch[1] + pitch[2]) / 3.0;
        torque = mw_torque_law_step(&c->law, m->gen_speed, mean, c->law.law.p_rated);
        if (p->region == 3) torque = dmin(torque, p->u0[3]);
    } else if (p->region == 3) {
        torque = p->u0[3];
    } else {
        torque = p->k_opt * m->gen_speed * m->gen_speed;
    }
    torque = dmin(dmax(torque, c->limits[2]), c->limits[3]);
    for (b = 0; b < 3; b++) p->udev[b] = pitch[b] - p->u0[b];
    p->udev[3] = torque - p->u0[3];
    for (b = 0; b < 3; b++) out->pitch[b] = pitch[b];
    out->torque = torque;
    /* region, schedule_wind, schedule_grid_wind, schedule_outside, estimator_outside */
    out->nlog = 5;
    out->log[0] = p->region;
    out->log[1] = c->sched.wind;
    out->log[2] = c->sched.grid[k];
    out->log[3] = mw_schedule_outside(&c->sched);
    out->log[4] = mw_schedule_estimator_outside(&c->sched);
    return 0;
}

static void point_free(mw_lqr_point *p)
{
    free(p->ad);
    free(p->bd);
    free(p->gain);
    free(p->y0);
    free(p->u0);
    free(p->x0d0);
    free(p->gi);
    free(p->xe);
    free(p->udev);
}

static void lqr_destroy(mw_ctrl *self)
{
    mw_lqr *c = (mw_lqr *)self;
    int i;
    if (c->pt)
        for (i = 0; i < c->n; i++) point_free(&c->pt[i]);
    free(c->pt);
    free(c->signals);
    free(c->y);
    free(c->work);
    mw_schedule_free(&c->sched);
    free(c);
}

static int point_read(const mw_input *in, int k, int n_signals, mw_lqr_point *p, char *msg)
{
    char pre[32];
    double s[7], *gi;
    int i, n;
    snprintf(pre, sizeof(pre), "point.%d.", k);
    if (mw_getp_vec(in, pre, "sizes", s, 7, msg)) return -1;
    for (i = 0; i < 7; i++) {
        if (s[i] != floor(s[i]) || s[i] < 0 || s[i] > 1000) {
            mw_msg(msg, "mpc-wt lqr-pio: input file '%s': key '%ssizes' value %d is %g, "
                   "expected a whole number in [0, 1000]", in->path, pre, i + 1, s[i]);
            return -1;
        }
    }
    p->nx = (int)s[0];
    p->nf = (int)s[1];
    p->ny = (int)s[2];
    p->nu = (int)s[3];
    p->ng = (int)s[4];
    p->region = (int)s[5];
    p->has_law = (int)s[6];
    if (p->nx < 1 || p->nu != 4 || p->ny != n_signals || p->ng < 1 || p->ng > 4
        || (p->region != 2 && p->region != 3) || p->has_law > 1) {
        mw_msg(msg, "mpc-wt lqr-pio: input file '%s': key '%ssizes' (%g %g %g %g %g %g %g) "
               "is not a design of this library: n_x >= 1, n_u 4, n_y the %d signals, 1-4 "
               "gain rows, region 2 or 3, has_torque_law 0 or 1", in->path, pre, s[0], s[1],
               s[2], s[3], s[4], s[5], s[6], n_signals);
        return -1;
    }
    n = p->nx + p->nf;
    if (!(p->ad = mw_getp_alloc_n(in, pre, "ad", n * n, msg))
        || !(p->bd = mw_getp_alloc_n(in, pre, "bd", n * (p->nu + p->ny), msg))
        || !(p->gain = mw_getp_alloc_n(in, pre, "gain", p->ng * n, msg))
        || !(p->y0 = mw_getp_alloc_n(in, pre, "y0", p->ny, msg))
        || !(p->u0 = mw_getp_alloc_n(in, pre, "u0", p->nu, msg))
        || !(p->x0d0 = mw_getp_alloc_n(in, pre, "x0d0", n, msg))
        || mw_getp(in, pre, "k_opt", &p->k_opt, msg)
        || mw_getp(in, pre, "pitch_floor", &p->pitch_floor, msg)
        || !(gi = mw_getp_alloc_n(in, pre, "gain_inputs", p->ng, msg)))
        return -1;
    p->gi = (int *)malloc((size_t)p->ng * sizeof(int));
    p->xe = (double *)calloc((size_t)n, sizeof(double));
    p->udev = (double *)calloc((size_t)p->nu, sizeof(double));
    if (!p->gi || !p->xe || !p->udev) {
        free(gi);
        mw_msg(msg, "mpc-wt lqr-pio: out of memory");
        return -1;
    }
    for (i = 0; i < p->ng; i++) {
        if (gi[i] != floor(gi[i]) || gi[i] < 0 || gi[i] > 2) {
            mw_msg(msg, "mpc-wt lqr-pio: input file '%s': key '%sgain_inputs' value %d is %g, "
                   "expected a pitch input 0, 1 or 2", in->path, pre, i + 1, gi[i]);
            free(gi);
            return -1;
        }
        p->gi[i] = (int)gi[i];
    }
    free(gi);
    if (p->region == 2 && !p->has_law && !(p->k_opt > 0)) {
        mw_msg(msg, "mpc-wt lqr-pio: input file '%s': design %d is region II without a torque "
               "law: key '%sk_opt' must be > 0, got %g", in->path, k, pre, p->k_opt);
        return -1;
    }
    return 0;
}

static int lqr_read(const mw_input *in, mw_ctrl *self, char *msg)
{
    mw_lqr *c = (mw_lqr *)self;
    int i, biggest = 0;
    if (mw_get(in, "dt", &c->dt, msg) || mw_get_int(in, "n_points", 1, 1000, &c->n, msg)
        || mw_getp_vec(in, "", "limits", c->limits, 5, msg)
        || mw_signals_read(in, "signals", "lqr-pio", &c->signals, &c->n_signals, msg))
        return -1;
    if (!(c->dt > 0) || !(c->limits[1] >= c->limits[0]) || !(c->limits[3] >= c->limits[2])) {
        mw_msg(msg, "mpc-wt lqr-pio: input file '%s': key 'dt' must be > 0 s (got %g) and "
               "'limits' hold pitch min <= max, torque min <= max (got %g %g %g %g)", in->path,
               c->dt, c->limits[0], c->limits[1], c->limits[2], c->limits[3]);
        return -1;
    }
    if (mw_schedule_read(in, "schedule.", c->dt, &c->sched, msg)) return -1;
    if (c->sched.n != c->n) {
        mw_msg(msg, "mpc-wt lqr-pio: input file '%s': key 'schedule.grid' has %d winds, "
               "n_points is %d", in->path, c->sched.n, c->n);
        return -1;
    }
    c->pt = (mw_lqr_point *)calloc((size_t)c->n, sizeof(mw_lqr_point));
    c->y = (double *)malloc((size_t)c->n_signals * sizeof(double));
    if (!c->pt || !c->y) {
        mw_msg(msg, "mpc-wt lqr-pio: out of memory");
        return -1;
    }
    for (i = 0; i < c->n; i++) {
        if (point_read(in, i, c->n_signals, &c->pt[i], msg)) return -1;
        if (c->pt[i].nx + c->pt[i].nf > biggest) biggest = c->pt[i].nx + c->pt[i].nf;
        if (i > 0 && (c->pt[i].nx != c->pt[0].nx || c->pt[i].nf != c->pt[0].nf)) {
            mw_msg(msg, "mpc-wt lqr-pio: input file '%s': design %d has %d states and %d "
                   "unknown inputs, design 0 %d and %d (a switch carries the estimate over)",
                   in->path, i, c->pt[i].nx, c->pt[i].nf, c->pt[0].nx, c->pt[0].nf);
            return -1;
        }
        c->has_law |= c->pt[i].has_law;
    }
    c->work = (double *)malloc((size_t)biggest * sizeof(double));
    if (!c->work) {
        mw_msg(msg, "mpc-wt lqr-pio: out of memory");
        return -1;
    }
    if (c->has_law && mw_torque_law_read(in, &c->law, msg)) return -1;
    c->base.dt = c->dt;
    return 0;
}

mw_ctrl *mw_lqr_new(const mw_input *in, char *msg)
{
    return mw_ctrl_new(sizeof(mw_lqr), "lqr-pio", lqr_step, lqr_destroy, lqr_read, in, msg);
}
