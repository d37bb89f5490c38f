/* The rotor-effective wind speed from what a turbine controller measures, and the wind
 * schedule that picks a gain-scheduled controller's design.
 *
 * An extended Kalman filter on the drivetrain's one-degree-of-freedom model with the wind as a
 * random walk (ROSCO's WE_Mode 2 in its simplest form; Simon 2006, ch. 13):
 *     J d omega / dt = Q_a(v, omega, theta) - N Q_g,   dv / dt = w,
 *     Q_a = 1/2 rho pi R^2 v^3 C_P(lambda, theta) / omega,   lambda = omega R / v,
 * C_P a bicubic tensor-product B-spline (FITPACK's knots and coefficients, evaluated with de
 * Boor's recurrence). The first step starts from the wind that balances the measured torque
 * (Brent's method). The schedule low-passes the estimate and moves to the nearest grid wind
 * once the wind is beyond the midpoint by the hysteresis. */
#include "mpcwt_discon.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MW_PI 3.14159265358979323846

static double dmin(double a, double b) { return a < b ? a : b; }
static double dmax(double a, double b) { return a > b ? a : b; }

/* the k + 1 B-spline basis functions of degree k non-zero at x and their derivatives */
static int basis(const double *t, int nt, int k, double x, double *out, double *dout)
{
    double left[8], right[8];
    int n = nt - k - 1, span = k, j, r;
    x = dmin(dmax(x, t[k]), t[n]);
    while (span < n - 1 && x >= t[span + 1]) span++;
    out[0] = 1.0;
    for (j = 1; j <= k; j++) {
        double saved = 0.0;
        left[j] = x - t[span + 1 - j];
        right[j] = t[span + j] - x;
        for (r = 0; r < j; r++) {
            double tmp = out[r] / (right[r + 1] + left[j - r]);
            out[r] = saved + right[r + 1] * tmp;
            saved = left[j - r] * tmp;
        }
        out[j] = saved;
        if (j == k - 1) {
            for (r = 0; r <= k; r++) {
                int i = span - k + r;
                double a = r >= 1 ? out[r - 1] / (t[i + k] - t[i]) : 0.0;
                double b = r <= k - 1 ? out[r] / (t[i + k + 1] - t[i + 1]) : 0.0;
                dout[r] = k * (a - b);
            }
        }
    }
    if (k == 0) dout[0] = 0.0;
    return span - k;
}

static void spline2(const mw_windest *e, double x, double y, double *val, double *dval)
{
    double bx[8], dbx[8], by[8], dby[8];
    int ix = basis(e->tx, e->ntx, e->kx, x, bx, dbx);
    int iy = basis(e->ty, e->nty, e->ky, y, by, dby);
    int ncy = e->nty - e->ky - 1, r, q;
    *val = 0.0;
    *dval = 0.0;
    for (r = 0; r <= e->kx; r++) {
        double row = 0.0;
        for (q = 0; q <= e->ky; q++) row += e->c[(ix + r) * ncy + iy + q] * by[q];
        *val += bx[r] * row;
        *dval += dbx[r] * row;
    }
}

static void aero_torque(const mw_windest *e, double wind, double rotor_speed, double pitch,
                        double *q, double *dq_dv, double *dq_dw)
{
    double v = dmax(wind, 0.1), w = dmax(rotor_speed, 1e-3), radius = e->radius;
    double lam = dmin(dmax(w * radius / v, e->tsr0), e->tsr1), cp, dcp;
    double g = 0.5 * e->rho * MW_PI * (radius * radius);
    spline2(e, lam, pitch, &cp, &dcp);
    *q = g * (v * v * v) * cp / w;
    *dq_dv = g * (3.0 * (v * v) * cp - (v * v * v) * dcp * lam / v) / w;
    *dq_dw = g * (v * v * v) * (dcp * radius / v / w - cp / (w * w));
}

static double residual(const mw_windest *e, double v, double w, double pitch, double tq)
{
    double q, a, b;
    aero_torque(e, v, w, pitch, &q, &a, &b);
    return q - e->gear * tq;
}

/* Brent's method on [xa, xb] with f(xa) f(xb) < 0 (Brent 1973, ch. 4) */
static double brent(const mw_windest *e, double w, double pitch, double tq, double xa,
                    double xb, double fa, double fb, double xtol)
{
    const double rtol = 8.881784197001252e-16;
    double xpre = xa, xcur = xb, fpre = fa, fcur = fb, xblk = 0.0, fblk = 0.0;
    double spre = 0.0, scur = 0.0;
    int i;
    if (fpre == 0.0) return xpre;
    if (fcur == 0.0) return xcur;
    for (i = 0; i < 100; i++) {
        double delta, sbis;
        if (fpre != 0.0 && fcur != 0.0 && (signbit(fpre) != signbit(fcur))) {
            xblk = xpre;
            fblk = fpre;
            spre = scur = xcur - xpre;
        }
        if (fabs(fblk) < fabs(fcur)) {
            xpre = xcur;
            xcur = xblk;
            xblk = xpre;
            fpre = fcur;
            fcur = fblk;
            fblk = fpre;
        }
        delta = (xtol + rtol * fabs(xcur)) / 2.0;
        sbis = (xblk - xcur) / 2.0;
        if (fcur == 0.0 || fabs(sbis) < delta) return xcur;
        if (fabs(spre) > delta && fabs(fcur) < fabs(fpre)) {
            double stry;
            if (xpre == xblk) {
                stry = -fcur * (xcur - xpre) / (fcur - fpre);
            } else {
                double dpre = (fpre - fcur) / (xpre - xcur);
                double dblk = (fblk - fcur) / (xblk - xcur);
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre));
            }
            if (2.0 * fabs(stry) < dmin(fabs(spre), 3.0 * fabs(sbis) - delta)) {
                spre = scur;
                scur = stry;
            } else {
                spre = sbis;
                scur = sbis;
            }
        } else {
            spre = sbis;
            scur = sbis;
        }
        xpre = xcur;
        fpre = fcur;
        if (fabs(scur) > delta)
            xcur += scur;
        else
            xcur += (sbis > 0.0 ? delta : -delta);
        fcur = residual(e, xcur, w, pitch, tq);
    }
    return xcur;
}

int mw_windest_read(const mw_input *in, const char *pre, mw_windest *e, char *msg)
{
    double deg[2], k[17];
    memset(e, 0, sizeof(*e));
    if (mw_getp_vec(in, pre, "spline_degrees", deg, 2, msg)
        || mw_getp_vec(in, pre, "constants", k, 17, msg))
        return -1;
    e->kx = (int)deg[0];
    e->ky = (int)deg[1];
    if (e->kx < 1 || e->kx > 5 || e->ky < 1 || e->ky > 5) {
        mw_msg(msg, "mpc-wt controller: input file '%s': key '%sspline_degrees' must be two "
               "integers in [1, 5], got %g %g", in->path, pre, deg[0], deg[1]);
        return -1;
    }
    e->tx = mw_getp_alloc(in, pre, "spline_tx", &e->ntx, msg);
    if (!e->tx) return -1;
    e->ty = mw_getp_alloc(in, pre, "spline_ty", &e->nty, msg);
    if (!e->ty) {
        mw_windest_free(e);
        return -1;
    }
    e->c = mw_getp_alloc_n(in, pre, "spline_c", (e->ntx - e->kx - 1) * (e->nty - e->ky - 1),
                           msg);
    if (!e->c) {
        mw_windest_free(e);
        return -1;
    }
    e->radius = k[0];
    e->rho = k[1];
    e->gear = k[2]; /* the low-speed shaft torque per generator torque, N / eta_gearbox */
    e->inertia = k[3];
    e->dt = k[4];
    e->q0 = k[5];
    e->q1 = k[6];
    e->r = k[7];
    e->vmin = k[8];
    e->vmax = k[9];
    e->tsr0 = k[10];
    e->tsr1 = k[11];
    e->p0_speed = k[12];
    e->p0_wind = k[13];
    e->start_gain = k[14];
    e->start_rated = k[15];
    e->start_speed = k[16];
    mw_windest_reset(e);
    return 0;
}

void mw_windest_free(mw_windest *e)
{
    free(e->tx);
    free(e->ty);
    free(e->c);
    e->tx = e->ty = e->c = NULL;
}

void mw_windest_reset(mw_windest *e)
{
    e->started = 0;
    e->p[0] = e->p0_speed;
    e->p[1] = e->p[2] = 0.0;
    e->p[3] = e->p0_wind;
    e->u[0] = e->u[1] = 0.0;
}

/* the torque schedule at a rotor speed: K w^2 below 0.99 x rated speed, the rated torque from
 * rated speed on, a line in between (mpc_wt.controllers.wind_estimator's docstring) */
static double start_torque(const mw_windest *e, double w)
{
    double w1 = 0.99 * e->start_speed, q1;
    if (w >= e->start_speed) return e->start_rated;
    if (w <= w1) return dmin(e->start_gain * w * w, e->start_rated);
    q1 = dmin(e->start_gain * w1 * w1, e->start_rated);
    return q1 + (e->start_rated - q1) * (w - w1) / (e->start_speed - w1);
}

double mw_windest_step(mw_windest *e, double rotor_speed, double pitch, double gen_torque)
{
    if (!e->started) {
        double lo = e->vmin, hi = e->vmax, a, b;
        if (gen_torque <= 0.0)      /* none measured yet (ServoDyn's first call) */
            gen_torque = start_torque(e, rotor_speed);
        a = residual(e, lo, rotor_speed, pitch, gen_torque);
        b = residual(e, hi, rotor_speed, pitch, gen_torque);
        e->x[0] = rotor_speed;
        if (a * b < 0.0)
            e->x[1] = brent(e, rotor_speed, pitch, gen_torque, lo, hi, a, b, 1e-6);
        else
            e->x[1] = fabs(a) < fabs(b) ? lo : hi;
        e->started = 1;
    } else {
        double w = e->x[0], v = e->x[1], q, dq_dv, dq_dw, h, x0, a, b;
        double p00 = e->p[0], p01 = e->p[1], p10 = e->p[2], p11 = e->p[3];
        double n00, n01, n10, n11, s, g0, g1, err;
        aero_torque(e, v, w, e->u[0], &q, &dq_dv, &dq_dw);
        h = e->dt / e->inertia;
        x0 = w + h * (q - e->gear * e->u[1]);
        a = 1.0 + h * dq_dw;
        b = h * dq_dv;
        n00 = a * (a * p00 + b * p10) + b * (a * p01 + b * p11) + e->q0;
        n01 = a * p01 + b * p11;
        n10 = a * p10 + b * p11;
        n11 = p11 + e->q1;
        s = n00 + e->r;
        g0 = n00 / s;
        g1 = n10 / s;
        err = rotor_speed - x0;
        e->x[0] = x0 + g0 * err;
        e->x[1] = dmin(dmax(v + g1 * err, e->vmin), e->vmax);
        e->p[0] = n00 - g0 * n00;
        e->p[1] = n01 - g0 * n01;
        e->p[2] = n10 - g1 * n00;
        e->p[3] = n11 - g1 * n01;
    }
    e->u[0] = pitch;
    e->u[1] = gen_torque;
    return e->x[1];
}

/* ---- the schedule ------------------------------------------------------------------- */
static int schedule_floor_read(const mw_input *in, const char *pre, mw_schedule *s, char *msg)
{
    double v[4];
    int i;
    s->floor_w = mw_getp_alloc(in, pre, "floor_winds", &s->n_floor, msg);
    if (!s->floor_w) return -1;
    s->floor_p = mw_getp_alloc_n(in, pre, "floor_pitches", s->n_floor, msg);
    if (!s->floor_p || mw_getp_vec(in, pre, "floor_limits", v, 4, msg)) return -1;
    for (i = 1; i < s->n_floor; i++) {
        if (!(s->floor_w[i] > s->floor_w[i - 1] && s->floor_p[i] > s->floor_p[i - 1])) {
            mw_msg(msg, "mpc-wt controller: input file '%s': keys '%sfloor_winds' and "
                   "'%sfloor_pitches' must both increase (value %d)", in->path, pre, pre, i + 1);
            return -1;
        }
    }
    s->floor_pitch = v[0];
    s->floor_pitch_speed = v[1];
    s->floor_speed = v[2];
    s->floor_wind3 = v[3];
    return 0;
}

/* the least design wind the measured collective pitch and rotor speed allow (-inf: none) */
static double schedule_floor(const mw_schedule *s, double pitch, double rotor_speed)
{
    double f = -HUGE_VAL;
    if (pitch > s->floor_pitch && rotor_speed > s->floor_pitch_speed) {
        int n = s->n_floor, i = 0;
        if (pitch <= s->floor_p[0]) {
            f = s->floor_w[0];
        } else if (pitch >= s->floor_p[n - 1]) {
            f = s->floor_w[n - 1];
        } else {                                           /* numpy.interp */
            while (s->floor_p[i + 1] < pitch) i++;
            f = s->floor_w[i] + (pitch - s->floor_p[i]) / (s->floor_p[i + 1] - s->floor_p[i])
                * (s->floor_w[i + 1] - s->floor_w[i]);
        }
    }
    if (rotor_speed > s->floor_speed) f = dmax(f, s->floor_wind3);
    return f;
}

int mw_schedule_read(const mw_input *in, const char *pre, double dt, mw_schedule *s, char *msg)
{
    char sub[64];
    double v[2];
    int i;
    memset(s, 0, sizeof(*s));
    s->dt = dt;
    s->grid = mw_getp_alloc(in, pre, "grid", &s->n, msg);
    if (!s->grid) return -1;
    for (i = 1; i < s->n; i++) {
        if (!(s->grid[i] > s->grid[i - 1])) {
            mw_msg(msg, "mpc-wt controller: input file '%s': key '%sgrid' must increase "
                   "(value %d is %g after %g)", in->path, pre, i + 1, s->grid[i],
                   s->grid[i - 1]);
            mw_schedule_free(s);
            return -1;
        }
    }
    s->mid = (double *)malloc((size_t)(s->n > 1 ? s->n - 1 : 1) * sizeof(double));
    if (!s->mid || mw_getp_vec(in, pre, "time_constant_hysteresis", v, 2, msg)) {
        if (!s->mid) mw_msg(msg, "mpc-wt controller: out of memory");
        mw_schedule_free(s);
        return -1;
    }
    for (i = 0; i + 1 < s->n; i++) s->mid[i] = 0.5 * (s->grid[i + 1] + s->grid[i]);
    s->tau = v[0];
    s->hyst = v[1];
    snprintf(sub, sizeof(sub), "%swindest.", pre);
    if (mw_windest_read(in, sub, &s->est, msg)) {
        mw_schedule_free(s);
        return -1;
    }
    snprintf(sub, sizeof(sub), "%sregion_floor", pre);
    if (mw_has(in, sub) && (mw_getp_int(in, pre, "region_floor", 0, 1, &s->has_floor, msg)
                            || (s->has_floor && schedule_floor_read(in, pre, s, msg)))) {
        mw_schedule_free(s);
        return -1;
    }
    mw_schedule_reset(s);
    return 0;
}

void mw_schedule_free(mw_schedule *s)
{
    free(s->grid);
    free(s->mid);
    free(s->floor_w);
    free(s->floor_p);
    s->grid = s->mid = s->floor_w = s->floor_p = NULL;
    mw_windest_free(&s->est);
}

void mw_schedule_reset(mw_schedule *s)
{
    mw_windest_reset(&s->est);
    s->started = 0;
    s->active = 0;
    s->from_estimator = 0;
}

/* the number of midpoints below x (Python's bisect_left) */
static int bisect_left(const double *a, int n, double x)
{
    int lo = 0, hi = n;
    while (lo < hi) {
        int m = (lo + hi) / 2;
        if (a[m] < x)
            lo = m + 1;
        else
            hi = m;
    }
    return lo;
}

int mw_schedule_update(mw_schedule *s, const mw_meas *m, int *switched)
{
    double pitch = (m->pitch[0] + m->pitch[1] + m->pitch[2]) / 3.0;
    int k = mw_schedule_update_wind(s, mw_windest_step(&s->est, m->rotor_speed, pitch,
                                                       m->gen_torque), m, switched);
    s->from_estimator = 1;
    return k;
}

int mw_windest_outside(const mw_windest *e)
{
    /* held at an end of its wind range, or at a tip-speed ratio beyond its C_P table's */
    double tsr;
    if (!e->started) return 0;
    if (e->x[1] <= e->vmin * (1.0 + 1e-9) || e->x[1] >= e->vmax * (1.0 - 1e-9)) return 1;
    tsr = e->x[0] * e->radius / e->x[1];
    return !(e->tsr0 <= tsr && tsr <= e->tsr1);
}

int mw_schedule_outside(const mw_schedule *s)
{
    return s->started && (s->wind < s->grid[0] - 1.0 || s->wind > s->grid[s->n - 1] + 1.0);
}

int mw_schedule_estimator_outside(const mw_schedule *s)
{
    return s->from_estimator && mw_windest_outside(&s->est);
}

int mw_schedule_update_wind(mw_schedule *s, double w, const mw_meas *m, int *switched)
{
    double a;
    int k, now;
    *switched = 0;
    s->from_estimator = 0;
    s->measured = w;
    if (s->has_floor && m)
        w = dmax(w, schedule_floor(s, (m->pitch[0] + m->pitch[1] + m->pitch[2]) / 3.0,
                                   m->rotor_speed));
    s->floored = w;
    if (!s->started) {
        s->wind = w;
        s->active = bisect_left(s->mid, s->n - 1, w);
        s->started = 1;
        return s->active;
    }
    a = s->tau == 0.0 ? 1.0 : dmin(1.0, s->dt / s->tau);
    s->wind += a * (w - s->wind);
    k = bisect_left(s->mid, s->n - 1, s->wind);
    now = s->active;
    if (k != now && fabs(s->wind - 0.5 * (s->grid[k] + s->grid[now])) > s->hyst) {
        s->active = k;
        *switched = 1;
    }
    return s->active;
}

/* ---- the Kalman filter --------------------------------------------------------------- */
int mw_kalman_read(const mw_input *in, const char *pre, int nu, mw_kalman *k, char *msg)
{
    double dims[2];
    memset(k, 0, sizeof(*k));
    if (mw_getp_vec(in, pre, "n_ny", dims, 2, msg)) return -1;
    k->n = (int)dims[0];
    k->ny = (int)dims[1];
    k->nu = nu;
    if (k->n < 1 || k->ny < 1 || k->n > 1000 || k->ny > 1000) {
        mw_msg(msg, "mpc-wt controller: input file '%s': key '%sn_ny' must be two sizes in "
               "[1, 1000], got %g %g", in->path, pre, dims[0], dims[1]);
        return -1;
    }
    if (!(k->a = mw_getp_alloc_n(in, pre, "a", k->n * k->n, msg))
        || !(k->b = mw_getp_alloc_n(in, pre, "b", k->n * nu, msg))
        || !(k->c = mw_getp_alloc_n(in, pre, "c", k->ny * k->n, msg))
        || !(k->d = mw_getp_alloc_n(in, pre, "d", k->ny * nu, msg))
        || !(k->gain = mw_getp_alloc_n(in, pre, "gain", k->n * k->ny, msg))
        || !(k->y0 = mw_getp_alloc_n(in, pre, "y0", k->ny, msg))) {
        mw_kalman_free(k);
        return -1;
    }
    k->xa = (double *)calloc((size_t)k->n, sizeof(double));
    k->work = (double *)calloc((size_t)(k->n + k->ny), sizeof(double));
    if (!k->xa || !k->work) {
        mw_msg(msg, "mpc-wt controller: out of memory");
        mw_kalman_free(k);
        return -1;
    }
    return 0;
}

void mw_kalman_free(mw_kalman *k)
{
    free(k->a);
    free(k->b);
    free(k->c);
    free(k->d);
    free(k->gain);
    free(k->y0);
    free(k->xa);
    free(k->work);
    memset(k, 0, sizeof(*k));
}

void mw_kalman_reset(mw_kalman *k)
{
    int i;
    for (i = 0; i < k->n; i++) k->xa[i] = 0.0;
    k->started = 0;
}

int mw_kalman_update(mw_kalman *k, const double *y, const double *u)
{
    int n = k->n, ny = k->ny, nu = k->nu, i, j, l;
    double *xp = k->work, *innov = k->work + n;
    for (j = 0; j < ny; j++)
        if (!mw_finite(y[j])) return -1;
    for (i = 0; i < n; i++) {
        double acc = 0.0;
        if (k->started) {
            for (l = 0; l < n; l++) acc += k->a[i * n + l] * k->xa[l];
            for (l = 0; l < nu; l++) acc += k->b[i * nu + l] * u[l];
        } else {
            acc = k->xa[i];
        }
        xp[i] = acc;
    }
    for (j = 0; j < ny; j++) {
        double acc = y[j] - k->y0[j];
        for (l = 0; l < n; l++) acc -= k->c[j * n + l] * xp[l];
        for (l = 0; l < nu; l++) acc -= k->d[j * nu + l] * u[l];
        innov[j] = acc;
    }
    for (i = 0; i < n; i++) {
        double acc = xp[i];
        for (j = 0; j < ny; j++) acc += k->gain[i * ny + j] * innov[j];
        k->xa[i] = acc;
    }
    k->started = 1;
    return 0;
}
