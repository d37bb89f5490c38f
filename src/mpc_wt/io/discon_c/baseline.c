/* The baseline: Jonkman's law (NREL/TP-500-38060, sec. 7) as mpc-wt designs it: a first-order
 * low-pass on the generator speed, a gain-scheduled PI on the filtered speed error with
 * GK = 1 / (1 + theta / theta_K) at the previous command, anti-windup and a bumpless start at
 * the measured pitch, the pitch-rate limit, and the torque law of regions 1.5, 2, 2.5 and 3
 * with its rate limit. The same operations in the same order as mpc-wt's compiled law. */
#include "mpcwt_discon.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MW_PI 3.14159265358979323846

#define MW_FF_KEEP 4096

/* the LIDAR feedforward (collective): the rotor mean of the beams' u_hat = v_LOS / cos(cone),
 * sampled every sample_dt, low-passed (first order, or second order with damping 0.7,
 * discretized exactly at the corner of the measured mean wind), stored under the time it
 * reaches the rotor (t + D / V_m) and read at t + lead; the static pitch curve of that wind is
 * the feedforward pitch, whose change enters the PI's integral */
typedef struct {
    int on, order, ncorner, ncurve, n_mean, started, len;
    double cos_cone, focus, alpha, sample_dt, tau_act, lead_given, delay;
    double *cw, *cc, *cv, *cp;
    double mean, vf, x[2], next, w_disc, corner, lead, tp, phi[4], gam[2];
    double *arr, *val;
    double ff_last, wind;           /* this step's feedforward pitch and filtered wind */
    int has_ff_last;
} mw_ff;

/* active power control (Clemens et al. 2022, eq 11): the power reference
 * P_r (1 - offset - amplitude sin(2 pi f t)) replaces rated power above rated; the PI's gains
 * KP GK(theta), KI GK(theta) of the designs at several power fractions interpolated on the
 * reference's fraction (the integral in pitch units, so a gain change moves no command), and
 * each change of the reference moving the pitch by dP_ref / (eta dP/dtheta) */
#define MW_APC_MAX 16
typedef struct {
    int on, n, saturated;
    double freq, amp, offset, p_full;
    double f[MW_APC_MAX], kp[MW_APC_MAX], ki[MW_APC_MAX], thk[MW_APC_MAX], dpdt[MW_APC_MAX];
    double p_ref, p_ref_last;
} mw_apc;

typedef struct {
    mw_ctrl base;
    mw_law law;
    mw_ff ff;
    mw_ibc ibc;
    mw_cipc cipc;
    mw_apc apc;
    /* state */
    double w_filt, integral, last_pitch, last_tq, gk;
    int started;
} mw_baseline;

static double dmin(double a, double b) { return a < b ? a : b; }
static double dmax(double a, double b) { return a > b ? a : b; }

double mw_law_torque(const mw_law *c, double w, double pitch, double p3)
{
    double tq;
    if (w >= c->w_rated || pitch >= c->rgn3_pitch) {
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

/* the minimum-pitch schedule: keys min_pitch_speeds [rad/s] (2..MW_MIN_PITCH_MAX, increasing)
 * and min_pitch_offsets [rad] (as many, >= 0) */
static int read_min_pitch(const mw_input *in, const char *pre, mw_law *c, char *msg)
{
    int n = 0, m = 0, i, bad = 0;
    double *w = mw_getp_alloc(in, pre, "min_pitch_speeds", &n, msg), *off;
    if (!w) return -1;
    off = mw_getp_alloc(in, pre, "min_pitch_offsets", &m, msg);
    if (!off) {
        free(w);
        return -1;
    }
    if (n != m || n < 2 || n > MW_MIN_PITCH_MAX) bad = 1;
    for (i = 0; !bad && i < n; i++)
        if (!mw_finite(w[i]) || !mw_finite(off[i]) || off[i] < 0.0 || (i > 0 && !(w[i] > w[i - 1])))
            bad = 1;
    if (bad) {
        mw_msg(msg, "mpc-wt baseline: input file '%s': %smin_pitch_speeds and %smin_pitch_offsets "
               "must hold as many values, 2 to %d, the speeds finite and increasing, the offsets "
               "finite and >= 0 rad (got %d and %d values)", in->path, pre, pre, MW_MIN_PITCH_MAX,
               n, m);
        free(w);
        free(off);
        return -1;
    }
    c->mp_n = n;
    memcpy(c->mp_w, w, (size_t)n * sizeof(double));
    memcpy(c->mp_off, off, (size_t)n * sizeof(double));
    free(w);
    free(off);
    return 0;
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
    /* region 3 at 1 deg above the fine pitch (Jonkman's VS_Rgn3MP, from the turbine's own) */
    c->rgn3_pitch = c->p_min + MW_PI / 180.0;
    return read_min_pitch(in, pre, c, msg);
}

double mw_law_min_pitch_offset(const mw_law *c, double w)
{
    return mw_interp(w, c->mp_w, c->mp_off, c->mp_n);
}

/* exp(A) of a 3 x 3 matrix: scaling and squaring of its Taylor series (to rounding) */
static void expm3(const double *a, double *e)
{
    double s[9], term[9], tmp[9], norm = 0.0;
    int i, j, k, l, sq = 0;
    for (i = 0; i < 9; i++) norm = dmax(norm, fabs(a[i]));
    while (norm * 3.0 > 0.5) {
        norm /= 2.0;
        sq++;
    }
    for (i = 0; i < 9; i++) s[i] = a[i] / ldexp(1.0, sq);
    for (i = 0; i < 9; i++) e[i] = term[i] = (i % 4 == 0) ? 1.0 : 0.0;
    for (k = 1; k <= 20; k++) {
        for (i = 0; i < 3; i++)
            for (j = 0; j < 3; j++) {
                double acc = 0.0;
                for (l = 0; l < 3; l++) acc += term[i * 3 + l] * s[l * 3 + j];
                tmp[i * 3 + j] = acc / k;
            }
        for (i = 0; i < 9; i++) {
            term[i] = tmp[i];
            e[i] += tmp[i];
        }
    }
    for (k = 0; k < sq; k++) {
        for (i = 0; i < 3; i++)
            for (j = 0; j < 3; j++) {
                double acc = 0.0;
                for (l = 0; l < 3; l++) acc += e[i * 3 + l] * e[l * 3 + j];
                tmp[i * 3 + j] = acc;
            }
        memcpy(e, tmp, sizeof(tmp));
    }
}

static void ff_set_corner(mw_ff *f, double vm)
{
    double w;
    f->tp = f->focus / vm;
    w = mw_interp(vm, f->cw, f->cc, f->ncorner);
    if (f->lead_given < 0.0) {
        double room = f->tp - f->tau_act - f->sample_dt;
        double need = room > 0 ? f->delay / room : HUGE_VAL;
        if (w < need && need < HUGE_VAL) w = need;
        f->lead = f->tau_act + f->delay / w;
    } else {
        f->lead = f->lead_given;
    }
    f->corner = w;
    if (!(fabs(w - f->w_disc) <= 0.005 * w)) {
        double a[9] = {0.0, 1.0, 0.0, -w * w, -1.4 * w, w * w, 0.0, 0.0, 0.0}, e[9];
        int i;
        for (i = 0; i < 9; i++) a[i] *= f->sample_dt;
        expm3(a, e);
        f->phi[0] = e[0];
        f->phi[1] = e[1];
        f->phi[2] = e[3];
        f->phi[3] = e[4];
        f->gam[0] = e[2];
        f->gam[1] = e[5];
        f->w_disc = w;
    }
}

/* this step's feedforward pitch [rad]; -1 on bad LIDAR data */
static int ff_step(mw_ff *f, const mw_meas *m, double *pitch, char *msg)
{
    double v;
    if (m->t >= f->next - 1e-9) {
        double u, arrival, w[3], taken;
        if (mw_lidar_winds(m, f->cos_cone, 0.0, w, &taken, "baseline", msg)) return -1;
        u = (w[0] + w[1] + w[2]) / 3.0;
        f->n_mean++;
        if (f->n_mean == 1)
            f->mean = u;
        else
            f->mean += dmax(1.0 / f->n_mean, f->alpha) * (u - f->mean);
        ff_set_corner(f, dmax(f->mean, 0.5));
        if (!f->started) {
            f->vf = u;
            f->x[0] = u;
            f->x[1] = 0.0;
            f->started = 1;
        } else if (f->order == 1) {
            double a = exp(-f->corner * f->sample_dt);
            f->vf = a * f->vf + (1.0 - a) * u;
        } else {
            double x0 = f->phi[0] * f->x[0] + f->phi[1] * f->x[1] + f->gam[0] * u;
            double x1 = f->phi[2] * f->x[0] + f->phi[3] * f->x[1] + f->gam[1] * u;
            f->x[0] = x0;
            f->x[1] = x1;
            f->vf = x0;
        }
        arrival = taken + f->tp;
        if (f->len > 0 && arrival <= f->arr[f->len - 1]) arrival = f->arr[f->len - 1] + 1e-6;
        f->arr[f->len] = arrival;
        f->val[f->len] = f->vf;
        f->len++;
        if (f->len > MW_FF_KEEP) {               /* keep what is still to arrive */
            int keep = 0;
            while (keep < f->len && f->arr[keep] < m->t - 1.0) keep++;
            memmove(f->arr, f->arr + keep, (size_t)(f->len - keep) * sizeof(double));
            memmove(f->val, f->val + keep, (size_t)(f->len - keep) * sizeof(double));
            f->len -= keep;
        }
        f->next = m->t + f->sample_dt;
    }
    {   /* the filtered wind at t + lead (held at the ends, as mpc-wt's list interpolation) */
        double x = m->t + f->lead;
        int k = 0;
        while (k < f->len && f->arr[k] <= x) k++;
        if (k == 0)
            v = f->val[0];
        else if (k == f->len)
            v = f->val[f->len - 1];
        else
            v = f->val[k - 1] + (f->val[k] - f->val[k - 1]) * (x - f->arr[k - 1])
                / (f->arr[k] - f->arr[k - 1]);
    }
    f->wind = v;
    *pitch = mw_interp(v, f->cv, f->cp, f->ncurve);
    return 0;
}

/* the power reference at t [W]; -1 with msg outside (0, rated power] */
static int apc_reference(mw_apc *a, const mw_law *c, double t, char *msg)
{
    double p = a->p_full * (1.0 - (a->offset + a->amp * sin(2.0 * MW_PI * a->freq * t)));
    if (!(mw_finite(p) && p > 0.0 && p <= c->p_rated * (1.0 + 1e-9))) {
        mw_msg(msg, "mpc-wt apc: the power reference at t = %g s is %g W; allowed: (0, rated "
               "power %g W]", t, p, c->p_rated);
        return -1;
    }
    a->p_ref = p;
    return 0;
}

/* the scheduled PI step of active power control: the pitch command [rad] */
static double apc_pitch(mw_baseline *b, double err, double pitch_meas, int first, double *off)
{
    const mw_law *c = &b->law;
    mw_apc *a = &b->apc;
    double kps[MW_APC_MAX], kis[MW_APC_MAX], dps[MW_APC_MAX], kp, ki, ff = 0.0, p_lo, p, step;
    double frac = a->p_ref / a->p_full;
    int j;
    for (j = 0; j < a->n; j++) {
        double gks = 1.0 / (1.0 + b->last_pitch / a->thk[j]);
        kps[j] = a->kp[j] * gks;
        kis[j] = a->ki[j] * gks;
        dps[j] = a->dpdt[j] / gks;
    }
    kp = mw_interp(frac, a->f, kps, a->n);
    ki = mw_interp(frac, a->f, kis, a->n);
    b->gk = kp / c->kp;
    if (first) {
        b->integral = pitch_meas - kp * err;
        a->p_ref_last = a->p_ref;
    }
    ff = (a->p_ref - a->p_ref_last) / c->eta / mw_interp(frac, a->f, dps, a->n);
    a->p_ref_last = a->p_ref;
    *off = mw_law_min_pitch_offset(c, b->w_filt);
    p_lo = c->p_min + *off;
    b->integral = dmin(dmax(b->integral + ki * err * c->dt + ff, p_lo), c->p_max);
    p = dmin(dmax(kp * err + b->integral, p_lo), c->p_max);
    step = c->rate * c->dt;
    p = dmin(dmax(p, b->last_pitch - step), b->last_pitch + step);
    a->saturated = p <= p_lo + 1e-9 && err < 0.0;
    return p;
}

/* the DISCON-form PI step: the pitch command [rad] */
static double pi_pitch(mw_baseline *b, double err, double pitch_meas, int first, double ffd,
                       double *off)
{
    const mw_law *c = &b->law;
    double gk = 1.0 / (1.0 + b->last_pitch / c->theta_k), lo, hi, p, step, p_lo;
    b->gk = gk;
    if (first) b->integral = (pitch_meas / gk - c->kp * err) / c->ki;
    b->integral += err * c->dt + ffd / (gk * c->ki);
    *off = mw_law_min_pitch_offset(c, b->w_filt);
    p_lo = c->p_min + *off;
    lo = p_lo / (gk * c->ki);
    hi = c->p_max / (gk * c->ki);
    b->integral = dmin(dmax(b->integral, lo), hi);
    p = gk * (c->kp * err + c->ki * b->integral);
    p = dmin(dmax(p, p_lo), c->p_max);
    step = c->rate * c->dt;
    return dmin(dmax(p, b->last_pitch - step), b->last_pitch + step);
}

/* the add-ons on the collective command p: IBC or Coleman IPC, with their logging channels */
static int addons_step(mw_baseline *b, const mw_meas *m, double p, mw_cmd *out, char *msg)
{
    double pc[3] = {p, p, p};
    int i, n = out->nlog;
    if (b->ibc.on) {                /* ibc_weight, ibc_gain, ibc_pitch_1..3 */
        if (mw_ibc_step(&b->ibc, m, b->law.dt, pc, out->pitch, msg)) return -1;
        out->log[n] = b->ibc.weight;
        out->log[n + 1] = b->ibc.gain;
        for (i = 0; i < 3; i++) out->log[n + 2 + i] = b->ibc.u[i];
        out->nlog = n + 5;
    } else if (b->cipc.on) {        /* ipc_weight, ipc_tilt_moment, ipc_yaw_moment,
                                       ipc_pitch_cos, ipc_pitch_sin */
        if (mw_cipc_step(&b->cipc, m, b->law.dt, pc, out->pitch, msg)) return -1;
        out->log[n] = b->cipc.weight;
        out->log[n + 1] = b->cipc.tilt;
        out->log[n + 2] = b->cipc.yaw;
        out->log[n + 3] = b->cipc.cyc_c;
        out->log[n + 4] = b->cipc.cyc_s;
        out->nlog = n + 5;
    }
    return 0;
}

static int baseline_step(mw_ctrl *self, const mw_meas *m, mw_cmd *out, char *msg)
{
    mw_baseline *b = (mw_baseline *)self;
    const mw_law *c = &b->law;
    double w = m->gen_speed, pitch_meas, err, p, tq, off, p3 = c->p_rated, ffd = 0.0;
    int first = !b->started;
    if (b->ff.on) {
        double ff;
        if (ff_step(&b->ff, m, &ff, msg)) return -1;
        ffd = b->ff.has_ff_last ? ff - b->ff.ff_last : 0.0;
        b->ff.ff_last = ff;
        b->ff.has_ff_last = 1;
    }
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
    if (b->apc.on && apc_reference(&b->apc, c, m->t, msg)) return -1;
    if (first) {
        b->w_filt = w;
        b->last_pitch = pitch_meas;
    }
    b->w_filt = c->a * b->w_filt + (1 - c->a) * w;
    err = b->w_filt - c->w_set;
    if (b->apc.on) {
        p = apc_pitch(b, err, pitch_meas, first, &off);
        p3 = b->apc.p_ref;
    } else {
        p = pi_pitch(b, err, pitch_meas, first, ffd, &off);
    }
    b->last_pitch = p;
    tq = dmin(mw_law_torque(c, b->w_filt, p - off, p3), c->tq_max);
    if (!first) {
        double d = c->tq_rate * c->dt;
        tq = dmin(dmax(tq, b->last_tq - d), b->last_tq + d);
    }
    b->last_tq = tq;
    b->started = 1;
    out->pitch[0] = out->pitch[1] = out->pitch[2] = p;
    out->torque = tq;
    /* gen_speed_filtered, speed_error, pitch_integral (of the speed error [rad]; in pitch
     * units [rad] with active power control), gain_schedule */
    out->log[0] = b->w_filt;
    out->log[1] = err;
    out->log[2] = b->integral;
    out->log[3] = b->gk;
    out->nlog = 4;
    if (b->ff.on) {                 /* ff_wind, ff_pitch, ff_mean_wind, ff_corner */
        out->log[4] = b->ff.wind;
        out->log[5] = b->ff.ff_last;
        out->log[6] = b->ff.mean;
        out->log[7] = b->ff.corner;
        out->nlog = 8;
    }
    if (b->apc.on) {                /* power_reference, apc_saturated */
        out->log[4] = b->apc.p_ref;
        out->log[5] = (double)b->apc.saturated;
        out->nlog = 6;
    }
    return addons_step(b, m, p, out, msg);
}

static void baseline_destroy(mw_ctrl *self)
{
    mw_baseline *b = (mw_baseline *)self;
    free(b->ff.cw);
    free(b->ff.cc);
    free(b->ff.cv);
    free(b->ff.cp);
    free(b->ff.arr);
    free(b->ff.val);
    mw_ibc_free(&b->ibc);
    mw_cipc_free(&b->cipc);
    free(self);
}

static int ff_read(const mw_input *in, mw_ff *f, char *msg)
{
    double v[7];
    int n;
    if (mw_getp_vec(in, "", "ff", v, 7, msg)) return -1;
    f->cos_cone = v[0];
    f->focus = v[1];
    f->sample_dt = v[2];
    f->alpha = dmin(1.0, v[2] / v[3]);
    f->tau_act = v[4];
    f->lead_given = v[5];
    f->order = (int)v[6];
    if (!(f->cos_cone > 0 && f->cos_cone <= 1) || !(f->focus > 0) || !(f->sample_dt > 0)
        || !(v[3] > 0) || (f->order != 1 && f->order != 2)) {
        mw_msg(msg, "mpc-wt baseline: input file '%s': key 'ff' needs cos(cone) in (0, 1], "
               "focus distance, sample period and mean time constant > 0, filter order 1 or 2",
               in->path);
        return -1;
    }
    f->delay = f->order == 1 ? 1.0 : 1.4;
    if (!(f->cw = mw_getp_alloc(in, "", "ff_corner_winds", &f->ncorner, msg))
        || !(f->cc = mw_getp_alloc_n(in, "", "ff_corners", f->ncorner, msg))
        || !(f->cv = mw_getp_alloc(in, "", "ff_curve_winds", &f->ncurve, msg))
        || !(f->cp = mw_getp_alloc_n(in, "", "ff_curve_pitch", f->ncurve, msg)))
        return -1;
    n = MW_FF_KEEP + 1;
    f->arr = (double *)calloc((size_t)n, sizeof(double));
    f->val = (double *)calloc((size_t)n, sizeof(double));
    if (!f->arr || !f->val) {
        mw_msg(msg, "mpc-wt baseline: out of memory");
        return -1;
    }
    f->next = -HUGE_VAL;
    f->w_disc = NAN;
    f->on = 1;
    return 0;
}

/* key "apc": frequency [Hz], amplitude, offset [-], the power the reference refers to [W];
 * "apc_schedule": per design (by increasing power fraction) its fraction, kp [s], ki [-],
 * theta_K [rad], dP/dtheta at fine pitch [W/rad] */
static int apc_read(const mw_input *in, mw_apc *a, char *msg)
{
    double v[4], *sch;
    int n = 0, j, bad = 0;
    if (mw_getp_vec(in, "", "apc", v, 4, msg)
        || !(sch = mw_getp_alloc(in, "", "apc_schedule", &n, msg)))
        return -1;
    if (n % 5 || n == 0 || n / 5 > MW_APC_MAX) bad = 1;
    a->n = n / 5;
    for (j = 0; !bad && j < a->n; j++) {
        a->f[j] = sch[5 * j];
        a->kp[j] = sch[5 * j + 1];
        a->ki[j] = sch[5 * j + 2];
        a->thk[j] = sch[5 * j + 3];
        a->dpdt[j] = sch[5 * j + 4];
        if (!(a->f[j] > 0 && a->f[j] <= 1) || (j > 0 && !(a->f[j] > a->f[j - 1]))
            || !(a->thk[j] != 0) || !(a->dpdt[j] != 0)) bad = 1;
    }
    free(sch);
    a->freq = v[0];
    a->amp = v[1];
    a->offset = v[2];
    a->p_full = v[3];
    if (bad || !(a->freq >= 0) || !(a->amp >= 0) || !(a->p_full > 0)) {
        mw_msg(msg, "mpc-wt apc: input file '%s': key 'apc' needs a frequency >= 0 Hz, an "
               "amplitude >= 0 and the power > 0 W; 'apc_schedule' 1 to %d designs of 5 values, "
               "their power fractions increasing in (0, 1], theta_K and dP/dtheta non-zero",
               in->path, MW_APC_MAX);
        return -1;
    }
    a->on = 1;
    return 0;
}

mw_ctrl *mw_baseline_new(const mw_input *in, char *msg)
{
    mw_baseline *b = (mw_baseline *)calloc(1, sizeof(mw_baseline));
    if (!b) {
        mw_msg(msg, "mpc-wt baseline: out of memory");
        return NULL;
    }
    {
        int ff = 0, ibc = 0, cipc = 0;
        if (mw_law_read(in, "", &b->law, msg) || mw_get_int(in, "feedforward", 0, 1, &ff, msg)
            || (ff && ff_read(in, &b->ff, msg))
            || (mw_has(in, "ibc") && mw_get_int(in, "ibc", 0, 1, &ibc, msg))
            || (ibc && mw_ibc_read(in, &b->ibc, msg))
            || (mw_has(in, "coleman_ipc") && mw_get_int(in, "coleman_ipc", 0, 1, &cipc, msg))
            || (cipc && mw_cipc_read(in, &b->cipc, msg))
            || (mw_has(in, "apc") && apc_read(in, &b->apc, msg))) {
            baseline_destroy(&b->base);
            return NULL;
        }
        if (ibc && cipc) {
            mw_msg(msg, "mpc-wt baseline: input file '%s': keys 'ibc' and 'coleman_ipc' are both "
                   "1; the law adds one of them to its collective command", in->path);
            baseline_destroy(&b->base);
            return NULL;
        }
    }
    b->base.dt = b->law.dt;
    b->base.step = baseline_step;
    b->base.destroy = baseline_destroy;
    return &b->base;
}

/* ---- the torque law in another controller -------------------------------------------- */
int mw_torque_law_read(const mw_input *in, mw_torque_law *t, char *msg)
{
    double v[4];
    if (mw_law_read(in, "law.", &t->law, msg) || mw_getp_vec(in, "", "law_torque", v, 4, msg))
        return -1;
    t->a = v[0];
    t->offset = v[1];
    t->lo = v[2];
    t->hi = v[3];
    t->started = 0;
    return 0;
}

double mw_torque_law_step(mw_torque_law *t, double gen_speed, double pitch, double power)
{
    double q;
    t->w = t->started ? t->a * t->w + (1.0 - t->a) * gen_speed : gen_speed;
    t->started = 1;
    /* the pitch counted from the minimum-pitch floor: below region 2 the largest below-rated
     * trim pitch, above it the schedule's at the filtered speed (0 where it is fine pitch) */
    if (t->w < t->law.w_rgn2)
        pitch -= t->offset;
    else
        pitch -= mw_law_min_pitch_offset(&t->law, t->w);
    q = mw_law_torque(&t->law, t->w, pitch, power);
    return q < t->lo ? t->lo : (q > t->hi ? t->hi : q);
}

double mw_torque_law_min_pitch(const mw_torque_law *t)
{
    if (!t->started) return -HUGE_VAL;
    return t->law.p_min + mw_law_min_pitch_offset(&t->law, t->w);
}

mw_ctrl *mw_ctrl_new(size_t size, const char *who,
                     int (*step)(mw_ctrl *, const mw_meas *, mw_cmd *, char *),
                     void (*destroy)(mw_ctrl *),
                     int (*read)(const mw_input *, mw_ctrl *, char *), const mw_input *in,
                     char *msg)
{
    mw_ctrl *c = (mw_ctrl *)calloc(1, size);
    if (!c) {
        mw_msg(msg, "mpc-wt %s: out of memory", who);
        return NULL;
    }
    c->step = step;
    c->destroy = destroy;
    if (read(in, c, msg)) {
        destroy(c);
        return NULL;
    }
    return c;
}
