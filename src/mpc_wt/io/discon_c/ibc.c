/* Individual blade control on the baseline (Pettas and Cheng 2018, fig. 3): each blade's root
 * out-of-plane moment high-passed, times the gain scheduled on the mean collective pitch,
 * band-stopped (and low-passed) at the rotor harmonics, faded in with the low-passed electrical
 * power, less the blades' mean (cyclic action only), added to the collective command within
 * the pitch limits and rate. The filters are second-order sections in transposed direct form
 * II, started at the steady state of their first input (scipy's sosfilt_zi). */
#include "mpcwt_discon.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double dmin(double a, double b) { return a < b ? a : b; }
static double dmax(double a, double b) { return a > b ? a : b; }

/* one sample of each blade through a cascade; zi (n x 2 x 3) in place, started at x's steady
 * state (zi1 per unit input) on the first call */
static void sos_step(const double *sos, const double *zi1, int n, double *zi, int *started,
                     const double *x, double *y)
{
    int c, k;
    if (!*started) {
        for (k = 0; k < n; k++)
            for (c = 0; c < 3; c++) {
                zi[(k * 2 + 0) * 3 + c] = zi1[k * 2 + 0] * x[c];
                zi[(k * 2 + 1) * 3 + c] = zi1[k * 2 + 1] * x[c];
            }
        *started = 1;
    }
    for (c = 0; c < 3; c++) {
        double v = x[c];
        for (k = 0; k < n; k++) {
            const double *s = sos + 6 * k;
            double *z0 = zi + (k * 2 + 0) * 3 + c, *z1 = zi + (k * 2 + 1) * 3 + c;
            double out = s[0] * v + *z0;
            *z0 = s[1] * v - s[4] * out + *z1;
            *z1 = s[2] * v - s[5] * out;
            v = out;
        }
        y[c] = v;
    }
}

int mw_ibc_step(mw_ibc *b, const mw_meas *m, double dt, const double *pc, double *out,
                char *msg)
{
    double hp[3], u[3], w, k, mean;
    int i;
    if (!mw_finite(m->flap[0] + m->flap[1] + m->flap[2]) || !mw_finite(m->gen_power)) {
        mw_msg(msg, "mpc-wt ibc: measured blade root out-of-plane moments (records 30-32) or "
               "electrical power (15) are not finite at t = %g s", m->t);
        return -1;
    }
    b->p_filt = b->has_p ? b->p_alpha * b->p_filt + (1.0 - b->p_alpha) * m->gen_power
                         : m->gen_power;
    b->has_p = 1;
    w = dmin(dmax((b->p_filt / b->rated - b->w_lo) / (b->w_hi - b->w_lo), 0.0), 1.0);
    k = mw_interp((pc[0] + pc[1] + pc[2]) / 3.0, b->gp, b->gg, b->ng);
    sos_step(b->hp, b->hp_zi1, b->nhp, b->hp_zi, &b->hp_started, m->flap, hp);
    for (i = 0; i < 3; i++) hp[i] *= k;
    sos_step(b->bs, b->bs_zi1, b->nbs, b->bs_zi, &b->bs_started, hp, u);
    for (i = 0; i < 3; i++) u[i] *= w;
    if (b->remove_mean) {
        mean = (u[0] + u[1] + u[2]) / 3.0;
        for (i = 0; i < 3; i++) u[i] -= mean;
    }
    for (i = 0; i < 3; i++) {
        double prev = b->has_last ? b->last[i] : m->pitch[i], d = b->rate * dt;
        double v = dmin(dmax(pc[i] + u[i], b->pmin), b->pmax);
        out[i] = b->last[i] = dmin(dmax(v, prev - d), prev + d);
    }
    b->has_last = 1;
    return 0;
}

static int read_sos(const mw_input *in, const char *key, const char *zkey, double **sos,
                    double **zi1, double **zi, int *n, char *msg)
{
    int c;
    if (!(*sos = mw_getp_alloc(in, "", key, &c, msg))) return -1;
    if (c % 6) {
        mw_msg(msg, "mpc-wt ibc: input file '%s': key '%s' needs second-order sections of 6 "
               "values, got %d values", in->path, key, c);
        return -1;
    }
    *n = c / 6;
    if (!(*zi1 = mw_getp_alloc_n(in, "", zkey, *n * 2, msg))) return -1;
    *zi = (double *)calloc((size_t)*n * 6, sizeof(double));
    if (!*zi) {
        mw_msg(msg, "mpc-wt ibc: out of memory");
        return -1;
    }
    return 0;
}

int mw_ibc_read(const mw_input *in, mw_ibc *b, char *msg)
{
    double v[8];
    int i;
    memset(b, 0, sizeof(*b));
    if (mw_getp_vec(in, "", "ibc_settings", v, 8, msg)
        || !(b->gp = mw_getp_alloc(in, "", "ibc_gain_pitch", &b->ng, msg))
        || !(b->gg = mw_getp_alloc_n(in, "", "ibc_gain", b->ng, msg))
        || read_sos(in, "ibc_input_sos", "ibc_input_zi", &b->hp, &b->hp_zi1, &b->hp_zi, &b->nhp,
                    msg)
        || read_sos(in, "ibc_output_sos", "ibc_output_zi", &b->bs, &b->bs_zi1, &b->bs_zi,
                    &b->nbs, msg))
        return -1;
    b->w_lo = v[0];
    b->w_hi = v[1];
    b->rated = v[2];
    b->p_alpha = v[3];
    b->pmin = v[4];
    b->pmax = v[5];
    b->rate = v[6];
    b->remove_mean = v[7] != 0.0;
    if (!(b->w_hi > b->w_lo) || !(b->rated > 0) || !(b->p_alpha >= 0 && b->p_alpha < 1)
        || !(b->pmax >= b->pmin) || !(b->rate > 0) || (v[7] != 0.0 && v[7] != 1.0)) {
        mw_msg(msg, "mpc-wt ibc: input file '%s': key 'ibc_settings' needs the weight's power "
               "fractions increasing, rated power > 0, power filter pole in [0, 1), pitch min "
               "<= max, a rate > 0 and the mean removal 0 or 1", in->path);
        return -1;
    }
    for (i = 1; i < b->ng; i++) {
        if (!(b->gp[i] > b->gp[i - 1])) {
            mw_msg(msg, "mpc-wt ibc: input file '%s': key 'ibc_gain_pitch' must increase "
                   "(value %d is %g after %g)", in->path, i + 1, b->gp[i], b->gp[i - 1]);
            return -1;
        }
    }
    b->on = 1;
    return 0;
}

void mw_ibc_free(mw_ibc *b)
{
    free(b->gp);
    free(b->gg);
    free(b->hp);
    free(b->hp_zi1);
    free(b->hp_zi);
    free(b->bs);
    free(b->bs_zi1);
    free(b->bs_zi);
}
