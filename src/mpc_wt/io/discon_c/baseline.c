/* The baseline: Jonkman's law (NREL/TP-500-38060, sec. 7) as mpc-wt designs it: a first-order
 * low-pass on the generator speed, a gain-scheduled PI on the filtered speed error with
 * GK = 1 / (1 + theta / theta_K) at the previous command, anti-windup and a bumpless start at
 * the measured pitch, the pitch-rate limit, and the torque law of regions 1.5, 2, 2.5 and 3
 * with its rate limit. The same operations in the same order as mpc-wt's compiled law. */
#include "mpcwt_discon.h"

#include <math.h>
#include <stdlib.h>

typedef struct {
    mw_ctrl base;
    /* parameters */
    double a, w_set, kp, ki, theta_k, dt, p_min, p_max, rate, tq_rate, tq_max;
    double w_cutin, w_rgn2, w_trans, w_rated, w_sync, slope15, slope25, k_opt, tq_cap;
    double p_rated, eta, tq_rated, one_deg;
    int constant_power;
    /* state */
    double w_filt, integral, last_pitch, last_tq;
    int started;
} mw_baseline;

static double dmin(double a, double b) { return a < b ? a : b; }
static double dmax(double a, double b) { return a > b ? a : b; }

static double law_torque(const mw_baseline *c, double w, double pitch, double p3)
{
    double tq;
    if (w >= c->w_rated || pitch >= c->one_deg) {
        if (c->constant_power) return p3 / c->eta / dmax(w, 1e-6);
        return c->tq_rated * p3 / c->p_rated;
    }
    if (w <= c->w_cutin) return 0.0;
    if (w < c->w_rgn2)
        tq = c->slope15 * (w - c->w_cutin);
    else if (w < c->w_trans)
        tq = c->k_opt * w * w;
    else
        tq = c->slope25 * (w - c->w_sync);
    return dmin(dmin(tq, c->tq_cap), p3 / c->eta / dmax(w, 1e-6));
}

static int baseline_step(mw_ctrl *self, const mw_meas *m, mw_cmd *out, char *msg)
{
    mw_baseline *c = (mw_baseline *)self;
    double w = m->gen_speed, pitch_meas, err, gk, lo, hi, p, step, tq;
    int first = !c->started;
    if (!mw_finite(w)) {
        mw_msg(msg, "mpc-wt baseline: measured generator speed (avrSWAP record 20) is not "
               "finite at t = %g s", m->t);
        return -1;
    }
    pitch_meas = (m->pitch[0] + m->pitch[1] + m->pitch[2]) / 3.0;
    if (!mw_finite(pitch_meas)) {
        mw_msg(msg, "mpc-wt baseline: measured blade pitch (avrSWAP records 4, 33, 34) is not "
               "finite at t = %g s", m->t);
        return -1;
    }
    if (first) {
        c->w_filt = w;
        c->last_pitch = pitch_meas;
    }
    c->w_filt = c->a * c->w_filt + (1 - c->a) * w;
    err = c->w_filt - c->w_set;
    gk = 1.0 / (1.0 + c->last_pitch / c->theta_k);
    if (first) c->integral = (pitch_meas / gk - c->kp * err) / c->ki;
    c->integral += err * c->dt;
    lo = c->p_min / (gk * c->ki);
    hi = c->p_max / (gk * c->ki);
    c->integral = dmin(dmax(c->integral, lo), hi);
    p = gk * (c->kp * err + c->ki * c->integral);
    p = dmin(dmax(p, c->p_min), c->p_max);
    step = c->rate * c->dt;
    p = dmin(dmax(p, c->last_pitch - step), c->last_pitch + step);
    c->last_pitch = p;
    tq = dmin(law_torque(c, c->w_filt, p, c->p_rated), c->tq_max);
    if (!first) {
        double d = c->tq_rate * c->dt;
        tq = dmin(dmax(tq, c->last_tq - d), c->last_tq + d);
    }
    c->last_tq = tq;
    c->started = 1;
    out->pitch[0] = out->pitch[1] = out->pitch[2] = p;
    out->torque = tq;
    return 0;
}

static void baseline_destroy(mw_ctrl *self)
{
    free(self);
}

mw_ctrl *mw_baseline_new(const mw_input *in, char *msg)
{
    mw_baseline *c = (mw_baseline *)calloc(1, sizeof(mw_baseline));
    double corner_hz, cp;
    if (!c) {
        mw_msg(msg, "mpc-wt baseline: out of memory");
        return NULL;
    }
    if (mw_get(in, "dt", &c->dt, msg) || mw_get(in, "speed_filter_corner_hz", &corner_hz, msg)
        || mw_get(in, "gen_speed_setpoint", &c->w_set, msg) || mw_get(in, "kp", &c->kp, msg)
        || mw_get(in, "ki", &c->ki, msg) || mw_get(in, "theta_k", &c->theta_k, msg)
        || mw_get(in, "pitch_min", &c->p_min, msg) || mw_get(in, "pitch_max", &c->p_max, msg)
        || mw_get(in, "pitch_rate_max", &c->rate, msg)
        || mw_get(in, "torque_rate_max", &c->tq_rate, msg)
        || mw_get(in, "torque_max", &c->tq_max, msg)
        || mw_get(in, "gen_speed_cutin", &c->w_cutin, msg)
        || mw_get(in, "gen_speed_region2", &c->w_rgn2, msg)
        || mw_get(in, "gen_speed_transition", &c->w_trans, msg)
        || mw_get(in, "gen_speed_rated", &c->w_rated, msg)
        || mw_get(in, "gen_speed_sync", &c->w_sync, msg)
        || mw_get(in, "slope_region15", &c->slope15, msg)
        || mw_get(in, "slope_region25", &c->slope25, msg)
        || mw_get(in, "k_opt", &c->k_opt, msg) || mw_get(in, "torque_cap", &c->tq_cap, msg)
        || mw_get(in, "rated_power", &c->p_rated, msg)
        || mw_get(in, "gen_efficiency", &c->eta, msg)
        || mw_get(in, "rated_torque", &c->tq_rated, msg)
        || mw_get(in, "region3_constant_power", &cp, msg)) {
        free(c);
        return NULL;
    }
    if (!(c->dt > 0) || !(corner_hz > 0) || !(c->ki != 0) || !(c->theta_k != 0)
        || !(c->eta > 0) || !(c->p_rated > 0) || !(c->p_max >= c->p_min)) {
        mw_msg(msg, "mpc-wt baseline: input file '%s': dt, speed_filter_corner_hz, "
               "gen_efficiency and rated_power must be > 0, ki and theta_k non-zero, "
               "pitch_max >= pitch_min (got dt = %g, corner %g Hz, ki = %g, theta_k = %g, "
               "efficiency %g, rated power %g, pitch %g..%g)", in->path, c->dt, corner_hz,
               c->ki, c->theta_k, c->eta, c->p_rated, c->p_min, c->p_max);
        free(c);
        return NULL;
    }
    c->a = exp(-2.0 * 3.14159265358979323846 * corner_hz * c->dt);
    c->constant_power = cp != 0.0;
    c->one_deg = 3.14159265358979323846 / 180.0;
    c->base.dt = c->dt;
    c->base.step = baseline_step;
    c->base.destroy = baseline_destroy;
    return &c->base;
}
