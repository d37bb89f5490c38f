/* The baseline: Jonkman's law (NREL/TP-500-38060, sec. 7) as mpc-wt designs it: a first-order
 * low-pass on the generator speed, a gain-scheduled PI on the filtered speed error with
 * GK = 1 / (1 + theta / theta_K) at the previous command, anti-windup and a bumpless start at
 * the measured pitch, the pitch-rate limit, and the torque law of regions 1.5, 2, 2.5 and 3
 * with its rate limit. The same operations in the same order as mpc-wt's compiled law. */
#include "mpcwt_discon.h"

#include <math.h>
#include <stdlib.h>

#define MW_PI 3.14159265358979323846

typedef struct {
    mw_ctrl base;
    mw_law law;
    /* state */
    double w_filt, integral, last_pitch, last_tq;
    int started;
} mw_baseline;

static double dmin(double a, double b) { return a < b ? a : b; }
static double dmax(double a, double b) { return a > b ? a : b; }

double mw_law_torque(const mw_law *c, double w, double pitch, double p3)
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

int mw_law_read(const mw_input *in, const char *pre, mw_law *c, char *msg)
{
    double corner_hz, cp;
    if (mw_getp(in, pre, "dt", &c->dt, msg)
        || mw_getp(in, pre, "speed_filter_corner_hz", &corner_hz, msg)
        || mw_getp(in, pre, "gen_speed_setpoint", &c->w_set, msg)
        || mw_getp(in, pre, "kp", &c->kp, msg) || mw_getp(in, pre, "ki", &c->ki, msg)
        || mw_getp(in, pre, "theta_k", &c->theta_k, msg)
        || mw_getp(in, pre, "pitch_min", &c->p_min, msg)
        || mw_getp(in, pre, "pitch_max", &c->p_max, msg)
        || mw_getp(in, pre, "pitch_rate_max", &c->rate, msg)
        || mw_getp(in, pre, "torque_rate_max", &c->tq_rate, msg)
        || mw_getp(in, pre, "torque_max", &c->tq_max, msg)
        || mw_getp(in, pre, "gen_speed_cutin", &c->w_cutin, msg)
        || mw_getp(in, pre, "gen_speed_region2", &c->w_rgn2, msg)
        || mw_getp(in, pre, "gen_speed_transition", &c->w_trans, msg)
        || mw_getp(in, pre, "gen_speed_rated", &c->w_rated, msg)
        || mw_getp(in, pre, "gen_speed_sync", &c->w_sync, msg)
        || mw_getp(in, pre, "slope_region15", &c->slope15, msg)
        || mw_getp(in, pre, "slope_region25", &c->slope25, msg)
        || mw_getp(in, pre, "k_opt", &c->k_opt, msg)
        || mw_getp(in, pre, "torque_cap", &c->tq_cap, msg)
        || mw_getp(in, pre, "rated_power", &c->p_rated, msg)
        || mw_getp(in, pre, "gen_efficiency", &c->eta, msg)
        || mw_getp(in, pre, "rated_torque", &c->tq_rated, msg)
        || mw_getp(in, pre, "region3_constant_power", &cp, msg))
        return -1;
    if (!(c->dt > 0) || !(corner_hz > 0) || !(c->ki != 0) || !(c->theta_k != 0)
        || !(c->eta > 0) || !(c->p_rated > 0) || !(c->p_max >= c->p_min)) {
        mw_msg(msg, "mpc-wt baseline: input file '%s': %sdt, %sspeed_filter_corner_hz, "
               "gen_efficiency and rated_power must be > 0, ki and theta_k non-zero, "
               "pitch_max >= pitch_min (got dt = %g, corner %g Hz, ki = %g, theta_k = %g, "
               "efficiency %g, rated power %g, pitch %g..%g)", in->path, pre, pre, c->dt,
               corner_hz, c->ki, c->theta_k, c->eta, c->p_rated, c->p_min, c->p_max);
        return -1;
    }
    c->a = exp(-2.0 * MW_PI * corner_hz * c->dt);
    c->constant_power = cp != 0.0;
    c->one_deg = MW_PI / 180.0;
    return 0;
}

static int baseline_step(mw_ctrl *self, const mw_meas *m, mw_cmd *out, char *msg)
{
    mw_baseline *b = (mw_baseline *)self;
    const mw_law *c = &b->law;
    double w = m->gen_speed, pitch_meas, err, gk, lo, hi, p, step, tq;
    int first = !b->started;
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
        b->w_filt = w;
        b->last_pitch = pitch_meas;
    }
    b->w_filt = c->a * b->w_filt + (1 - c->a) * w;
    err = b->w_filt - c->w_set;
    gk = 1.0 / (1.0 + b->last_pitch / c->theta_k);
    if (first) b->integral = (pitch_meas / gk - c->kp * err) / c->ki;
    b->integral += err * c->dt;
    lo = c->p_min / (gk * c->ki);
    hi = c->p_max / (gk * c->ki);
    b->integral = dmin(dmax(b->integral, lo), hi);
    p = gk * (c->kp * err + c->ki * b->integral);
    p = dmin(dmax(p, c->p_min), c->p_max);
    step = c->rate * c->dt;
    p = dmin(dmax(p, b->last_pitch - step), b->last_pitch + step);
    b->last_pitch = p;
    tq = dmin(mw_law_torque(c, b->w_filt, p, c->p_rated), c->tq_max);
    if (!first) {
        double d = c->tq_rate * c->dt;
        tq = dmin(dmax(tq, b->last_tq - d), b->last_tq + d);
    }
    b->last_tq = tq;
    b->started = 1;
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
    mw_baseline *b = (mw_baseline *)calloc(1, sizeof(mw_baseline));
    if (!b) {
        mw_msg(msg, "mpc-wt baseline: out of memory");
        return NULL;
    }
    if (mw_law_read(in, "", &b->law, msg)) {
        free(b);
        return NULL;
    }
    b->base.dt = b->law.dt;
    b->base.step = baseline_step;
    b->base.destroy = baseline_destroy;
    return &b->base;
}
