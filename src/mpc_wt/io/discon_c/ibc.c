/* Individual blade control on the baseline (Pettas and Cheng 2018, fig. 3): each blade's root
 * out-of-plane moment high-passed, times the gain scheduled on the mean collective pitch,
 * band-stopped (and low-passed) at the rotor harmonics, faded in with the low-passed electrical
 * power, less the blades' mean (cyclic action only), each blade's within its largest amplitude,
 * added to the collective command within
 * the pitch limits and rate. The filters are second-order sections in transposed direct form
 * II, started at the steady state of their first input (scipy's sosfilt_zi). */
#include "mpcwt_discon.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double dmin(double a, double b) { return a < b ? a : b; }
static double dmax(double a, double b) { return a > b ? a : b; }

#define MW_PI_3 1.04719755119659774615  /* pi / 3 */

/* the low-passed electrical power's fade-in weight (no seed while the power is 0, as at
 * ServoDyn's first call) */
static double fade_in(mw_addon *a, double p)
{
    if (a->has_p || p > 0.0) {
        a->p_filt = a->has_p ? a->p_alpha * a->p_filt + (1.0 - a->p_alpha) * p : p;
        a->has_p = 1;
    }
    return dmin(dmax((a->p_filt / a->rated - a->w_lo) / (a->w_hi - a->w_lo), 0.0), 1.0);
}

/* the add-ons' common settings v[0..6] (the fade-in's power fractions, the power, the power
 * filter's pole, the pitch limits and rate) into a; 0 where they are unusable */
static int addon_read(const double *v, mw_addon *a)
{
    a->w_lo = v[0];
    a->w_hi = v[1];
    a->rated = v[2];
    a->p_alpha = v[3];
    a->pmin = v[4];
    a->pmax = v[5];
    a->rate = v[6];
    return v[1] > v[0] && v[2] > 0 && v[3] >= 0 && v[3] < 1 && v[5] >= v[4] && v[6] > 0;
}

/* a schedule's breakpoints increase; -1 with msg naming the key */
static int increasing(const mw_input *in, const char *who, const char *key, const double *x,
                      int n, char *msg)
{
    int i;
    for (i = 1; i < n; i++) {
        if (!(x[i] > x[i - 1])) {
            mw_msg(msg, "mpc-wt %s: input file '%s': key '%s' must increase (value %d is %g "
                   "after %g)", who, in->path, key, i + 1, x[i], x[i - 1]);
            return -1;
        }
    }
    return 0;
}

void mw_sos_step(mw_sos *f, const double *x, double *y)
{
    int c, k, nch = f->nch;
    if (!f->started) {
        for (k = 0; k < f->n; k++)
            for (c = 0; c < nch; c++) {
                f->zi[(k * 2 + 0) * nch + c] = f->zi1[k * 2 + 0] * x[c];
                f->zi[(k * 2 + 1) * nch + c] = f->zi1[k * 2 + 1] * x[c];
            }
        f->started = 1;
    }
    for (c = 0; c < nch; c++) {
        double v = x[c];
        for (k = 0; k < f->n; k++) {
            const double *s = f->sos + 6 * k;
            double *z0 = f->zi + (k * 2 + 0) * nch + c, *z1 = f->zi + (k * 2 + 1) * nch + c;
            double out = s[0] * v + *z0;
            *z0 = s[1] * v - s[4] * out + *z1;
            *z1 = s[2] * v - s[5] * out;
            v = out;
        }
        y[c] = v;
    }
}

int mw_sos_read(const mw_input *in, const char *who, const char *key, const char *zkey,
                int nch, mw_sos *f, char *msg)
{
    int c;
    f->nch = nch;
    f->started = 0;
    if (!(f->sos = mw_getp_alloc(in, "", key, &c, msg))) return -1;
    if (c % 6 || c == 0) {
        mw_msg(msg, "mpc-wt %s: input file '%s': key '%s' needs second-order sections of 6 "
               "values, got %d values", who, in->path, key, c);
        return -1;
    }
    f->n = c / 6;
    if (!(f->zi1 = mw_getp_alloc_n(in, "", zkey, f->n * 2, msg))) return -1;
    f->zi = (double *)calloc((size_t)(f->n * 2 * nch), sizeof(double));
    if (!f->zi) {
        mw_msg(msg, "mpc-wt %s: out of memory", who);
        return -1;
    }
    return 0;
}

void mw_sos_free(mw_sos *f)
{
    free(f->sos);
    free(f->zi1);
    free(f->zi);
}

/* the pitch rate the collective's first: the collective moves from c_last toward c_target
 * by at most d, and each blade's own part (parts[i]) from a_last[i] within what that leaves;
 * the blades' demands within the pitch limits into out; the new collective returned */
static double collective_first(double c_last, const double *a_last, double c_target,
                               const double *parts, double d, double pmin, double pmax,
                               double *out)
{
    double c_new = dmin(dmax(c_target, c_last - d), c_last + d);
    double budget = d - fabs(c_new - c_last);
    int i;
    for (i = 0; i < 3; i++) {
        double a = dmin(dmax(parts[i], a_last[i] - budget), a_last[i] + budget);
        out[i] = dmin(dmax(c_new + a, pmin), pmax);
    }
    return c_new;
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
    w = fade_in(&b->a, m->gen_power);
    k = mw_interp((pc[0] + pc[1] + pc[2]) / 3.0, b->gp, b->gg, b->ng);
    mw_sos_step(&b->hp, m->flap, hp);
    for (i = 0; i < 3; i++) hp[i] *= k;
    mw_sos_step(&b->bs, hp, u);
    for (i = 0; i < 3; i++) u[i] *= w;
    if (b->remove_mean) {
        mean = (u[0] + u[1] + u[2]) / 3.0;
        for (i = 0; i < 3; i++) u[i] -= mean;
    }
    for (i = 0; i < 3; i++) u[i] = b->u[i] = dmin(dmax(u[i], -b->amp), b->amp);
    b->weight = w;
    b->gain = k;
    {
        /* clipped blade by blade, a collective at the rate fell behind the baseline's */
        double prev[3], a_last[3], parts[3], c_last, c_mean;
        for (i = 0; i < 3; i++) prev[i] = b->has_last ? b->last[i] : m->pitch[i];
        c_last = (prev[0] + prev[1] + prev[2]) / 3.0;
        c_mean = (pc[0] + pc[1] + pc[2]) / 3.0;
        for (i = 0; i < 3; i++) {
            a_last[i] = prev[i] - c_last;
            parts[i] = pc[i] - c_mean + u[i];
        }
        collective_first(c_last, a_last, c_mean, parts, b->a.rate * dt, b->a.pmin, b->a.pmax,
                         out);
        for (i = 0; i < 3; i++) b->last[i] = out[i];
    }
    b->has_last = 1;
    return 0;
}

int mw_ibc_read(const mw_input *in, mw_ibc *b, char *msg)
{
    double v[9];
    memset(b, 0, sizeof(*b));
    if (mw_getp_vec(in, "", "ibc_settings", v, 9, msg)
        || !(b->gp = mw_getp_alloc(in, "", "ibc_gain_pitch", &b->ng, msg))
        || !(b->gg = mw_getp_alloc_n(in, "", "ibc_gain", b->ng, msg))
        || mw_sos_read(in, "ibc", "ibc_input_sos", "ibc_input_zi", 3, &b->hp, msg)
        || mw_sos_read(in, "ibc", "ibc_output_sos", "ibc_output_zi", 3, &b->bs, msg))
        return -1;
    b->remove_mean = v[7] != 0.0;
    b->amp = v[8];
    if (!addon_read(v, &b->a) || (v[7] != 0.0 && v[7] != 1.0) || !(b->amp > 0)) {
        mw_msg(msg, "mpc-wt ibc: input file '%s': key 'ibc_settings' needs the weight's power "
               "fractions increasing, rated power > 0, power filter pole in [0, 1), pitch min "
               "<= max, a rate > 0, the mean removal 0 or 1 and a largest amplitude > 0",
               in->path);
        return -1;
    }
    if (increasing(in, "ibc", "ibc_gain_pitch", b->gp, b->ng, msg)) return -1;
    b->on = 1;
    return 0;
}

void mw_ibc_free(mw_ibc *b)
{
    free(b->gp);
    free(b->gg);
    mw_sos_free(&b->hp);
    mw_sos_free(&b->bs);
}

/* ---- Coleman-frame integral IPC ------------------------------------------------------ */
int mw_cipc_step(mw_cipc *b, const mw_meas *m, double dt, const double *pc, double *out,
                 char *msg)
{
    double psi = m->azimuth, c[3], s[3], w, k, phi, cp, sp, amp, c_mean, c_new, parts[3];
    double d = b->a.rate * dt;
    int i;
    if (!mw_finite(m->flap[0] + m->flap[1] + m->flap[2]) || !mw_finite(psi)
        || !mw_finite(m->gen_power)) {
        mw_msg(msg, "mpc-wt coleman-ipc: measured blade root out-of-plane moments (records "
               "30-32), azimuth (60) or electrical power (15) are not finite at t = %g s", m->t);
        return -1;
    }
    for (i = 0; i < 3; i++) {
        c[i] = cos(psi + i * 2.0 * MW_PI_3);
        s[i] = sin(psi + i * 2.0 * MW_PI_3);
    }
    /* Coleman transform (Bossanyi 2003): M_tilt, M_yaw = 2/3 sum M_i (cos, sin) psi_i */
    b->tilt = 2.0 / 3.0 * (m->flap[0] * c[0] + m->flap[1] * c[1] + m->flap[2] * c[2]);
    b->yaw = 2.0 / 3.0 * (m->flap[0] * s[0] + m->flap[1] * s[1] + m->flap[2] * s[2]);
    w = fade_in(&b->a, m->gen_power);
    c_mean = (pc[0] + pc[1] + pc[2]) / 3.0;
    k = mw_interp(c_mean, b->gp, b->gk, b->ng);
    phi = mw_interp(c_mean, b->gp, b->gphi, b->ng);
    cp = cos(phi);
    sp = sin(phi);
    b->th_c -= w * k * (cp * b->tilt + sp * b->yaw) * dt;
    b->th_s -= w * k * (-sp * b->tilt + cp * b->yaw) * dt;
    amp = hypot(b->th_c, b->th_s);
    if (amp > b->amp) {             /* anti-windup: the amplitude clamped */
        b->th_c *= b->amp / amp;
        b->th_s *= b->amp / amp;
    }
    b->weight = w;
    b->cyc_c = w * b->th_c;
    b->cyc_s = w * b->th_s;
    if (!b->has_last) {             /* from the measured pitch at the first step */
        b->c_last = (m->pitch[0] + m->pitch[1] + m->pitch[2]) / 3.0;
        for (i = 0; i < 3; i++) b->a_last[i] = m->pitch[i] - b->c_last;
        b->has_last = 1;
    }
    /* the collective's part moves first within the rate, the cyclic within what is left */
    for (i = 0; i < 3; i++) parts[i] = pc[i] - c_mean + (b->cyc_c * c[i] + b->cyc_s * s[i]);
    c_new = collective_first(b->c_last, b->a_last, c_mean, parts, d, b->a.pmin, b->a.pmax, out);
    b->c_last = c_new;
    for (i = 0; i < 3; i++) b->a_last[i] = out[i] - c_new;
    return 0;
}

int mw_cipc_read(const mw_input *in, mw_cipc *b, char *msg)
{
    double v[8];
    memset(b, 0, sizeof(*b));
    if (mw_getp_vec(in, "", "coleman_settings", v, 8, msg)
        || !(b->gp = mw_getp_alloc(in, "", "coleman_pitch", &b->ng, msg))
        || !(b->gk = mw_getp_alloc_n(in, "", "coleman_ki", b->ng, msg))
        || !(b->gphi = mw_getp_alloc_n(in, "", "coleman_azimuth_offset", b->ng, msg)))
        return -1;
    b->amp = v[7];
    if (!addon_read(v, &b->a) || !(b->amp > 0)) {
        mw_msg(msg, "mpc-wt coleman-ipc: input file '%s': key 'coleman_settings' needs the "
               "weight's power fractions increasing, rated power > 0, power filter pole in "
               "[0, 1), pitch min <= max, a rate > 0 and a largest amplitude > 0", in->path);
        return -1;
    }
    if (increasing(in, "coleman-ipc", "coleman_pitch", b->gp, b->ng, msg)) return -1;
    b->on = 1;
    return 0;
}

void mw_cipc_free(mw_cipc *b)
{
    free(b->gp);
    free(b->gk);
    free(b->gphi);
}
