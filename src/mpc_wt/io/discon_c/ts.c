/* Clemens et al.'s Takagi-Sugeno controller and wind observer (Clemens et al. 2022, eqs 3 and
 * 7-10): linear models at the vertices of a grid over the rotor-effective wind and the power
 * reduction, blended by triangular memberships of the estimated wind.
 *
 * The observer's state xi = [x; v] (the plant's states and the rotor-effective wind) moves over
 * a period as the blend of exact zero-order-hold maps, one per vertex (weights h_i) or, when the
 * vertices measure differently (accelerations), one per pair of vertices active together
 * (weights h_i h_j):
 *     xi <- sum_k w_k (Phi_k xi + Gamma_k [u; y; 1]).
 * The parallel-distributed law (eq 7) then blends the vertex gains at the new estimate,
 *     u = sum_i h_i (u0_i - K_i (x - x0_i) - K_q,i q),
 * q the integral of the rotor speed's deviation (held while an applied input saturates), the
 * pitch kept to what the actuator can follow from the measured pitch; above the last vertex
 * wind the pitch follows the last cell's slope. The generator torque is the
 * baseline's schedule on the low-passed generator speed (or the TS law's own). The estimate
 * starts at the vertex equilibrium whose pitch is the first measured pitch. */
#include "mpcwt_discon.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    mw_ctrl base;
    int nv, nw, nr, n, nu, ny, nk, nt, ki, src, own_torque, has_law, started;
    double dt, limits[5], rated_power;
    int apc;                        /* a power reduction over time (eq 11) */
    double apc_f, apc_a, apc_o;     /* Delta P = offset + amplitude sin(2 pi f t) */
    double *wg, *rg, *phi, *gam, *x0, *u0, *kk, *eq_wind, *eq_pitch;
    int *terms, *signals, n_signals;
    /* state and scratch */
    double *xi, *xn, *w, *h, *y, u[2], q;
    mw_torque_law law;
} mw_ts;

static double dmin(double a, double b) { return a < b ? a : b; }
static double dmax(double a, double b) { return a > b ? a : b; }

/* the clipped premise's cell k on a grid and the hat weights of its two ends */
static int hat(const double *g, int n, double s, double *w0, double *w1)
{
    double c = dmin(dmax(s, g[0]), g[n - 1]), f;
    int k = 0;
    if (n == 1) {
        *w0 = 1.0;
        *w1 = 0.0;
        return 0;
    }
    while (k < n - 2 && g[k + 1] < c) k++;           /* numpy's searchsorted(left) - 1 */
    f = (c - g[k]) / (g[k + 1] - g[k]);
    *w0 = 1.0 - f;
    *w1 = f;
    return k;
}

/* whether the premise s lies outside the grid (and is clipped to it) */
static int outside(const double *g, int n, double s)
{
    return s < g[0] || s > g[n - 1];
}

/* the tensor-product hats of eq 3 at (v, dp), vertex (a, b) at a n_r + b */
static void memberships(const mw_ts *c, double v, double dp, double *h)
{
    double wa[2], wb[2];
    int ka = hat(c->wg, c->nw, v, &wa[0], &wa[1]), kb = hat(c->rg, c->nr, dp, &wb[0], &wb[1]);
    int i, j;
    memset(h, 0, (size_t)c->nv * sizeof(double));
    for (i = 0; i < 2; i++) {
        if (wa[i] == 0.0 || ka + i >= c->nw) continue;
        for (j = 0; j < 2; j++) {
            if (wb[j] == 0.0 || kb + j >= c->nr) continue;
            h[(ka + i) * c->nr + kb + j] += wa[i] * wb[j];
        }
    }
}

/* the observer's start: the equilibrium of the wind whose vertex pitch is the measured one */
static void start(mw_ts *c, double pitch)
{
    double v = mw_interp(pitch, c->eq_pitch, c->eq_wind, c->nw), dp0 = c->rg[0];
    int i, j;
    memberships(c, v, dp0, c->h);
    for (j = 0; j < c->n - 1; j++) c->xi[j] = 0.0;
    c->u[0] = c->u[1] = 0.0;
    for (i = 0; i < c->nv; i++) {
        for (j = 0; j < c->n - 1; j++) c->xi[j] += c->h[i] * c->x0[(size_t)i * (c->n - 1) + j];
        for (j = 0; j < 2; j++) c->u[j] += c->h[i] * c->u0[(size_t)i * c->nu + j];
    }
    c->xi[c->n - 1] = v;
    c->started = 1;
}

/* the observer over the last period (blended zero-order-hold maps), at power reduction dp */
static void observe(mw_ts *c, double dp)
{
    int n = c->n, m = c->nu + c->ny + 1, k, i, j;
    memberships(c, c->xi[n - 1], dp, c->h);
    for (j = 0; j < c->nu; j++) c->w[j] = c->u[j];
    for (j = 0; j < c->ny; j++) c->w[c->nu + j] = c->y[j];
    c->w[c->nu + c->ny] = 1.0;
    memset(c->xn, 0, (size_t)n * sizeof(double));
    for (k = 0; k < c->nt; k++) {
        double wk = c->h[c->terms[2 * k]];
        const double *phi = c->phi + (size_t)k * n * n, *gam = c->gam + (size_t)k * n * m;
        if (c->terms[2 * k + 1] >= 0) wk *= c->h[c->terms[2 * k + 1]];
        if (wk == 0.0) continue;
        for (i = 0; i < n; i++) {
            double a = 0.0, b = 0.0;
            for (j = 0; j < n; j++) a += phi[(size_t)i * n + j] * c->xi[j];
            for (j = 0; j < m; j++) b += gam[(size_t)i * m + j] * c->w[j];
            c->xn[i] += wk * (a + b);
        }
    }
    memcpy(c->xi, c->xn, (size_t)n * sizeof(double));
}

/* the parallel-distributed law at the new estimate and power reduction dp; returns the
 * integral to keep */
static double law_pdc(mw_ts *c, double dp, double *out)
{
    int n = c->n, nx = n - 1, i, r, j;
    double q = c->q, v = c->xi[n - 1], top = c->wg[c->nw - 1];
    memberships(c, v, dp, c->h);
    if (c->ki >= 0) {
        double ref = 0.0;
        for (i = 0; i < c->nv; i++) ref += c->h[i] * c->x0[(size_t)i * nx + c->ki];
        q = c->q + ((c->src >= 0 ? c->y[c->src] : c->xi[c->ki]) - ref) * c->dt;
    }
    out[0] = out[1] = 0.0;
    for (i = 0; i < c->nv; i++) {
        if (c->h[i] == 0.0) continue;
        for (r = 0; r < c->nu; r++) {
            const double *k = c->kk + ((size_t)i * c->nu + r) * c->nk;
            double acc = c->u0[(size_t)i * c->nu + r];
            for (j = 0; j < nx; j++) acc -= k[j] * (c->xi[j] - c->x0[(size_t)i * nx + j]);
            if (c->ki >= 0) acc -= k[nx] * q;
            out[r] += c->h[i] * acc;
        }
    }
    if (c->nw > 1 && v > top) {       /* beyond the last vertex its pitch schedule goes on */
        double w0, w1, slope = 0.0;
        int kb = hat(c->rg, c->nr, dp, &w0, &w1), b;
        for (b = 0; b < 2; b++) {
            int ib = kb + b, last = (c->nw - 1) * c->nr + ib, prev = (c->nw - 2) * c->nr + ib;
            double wb = b == 0 ? w0 : w1;
            if (wb == 0.0 || ib >= c->nr) continue;
            slope += wb * (c->u0[(size_t)last * c->nu] - c->u0[(size_t)prev * c->nu])
                     / (top - c->wg[c->nw - 2]);
        }
        out[0] += slope * (v - top);
    }
    return q;
}

static int ts_step(mw_ctrl *self, const mw_meas *m, mw_cmd *out, char *msg)
{
    mw_ts *c = (mw_ts *)self;
    double raw[2], pitch, torque, q, lo, hi, dp = 0.0;
    int b, clipped;
    if (mw_signals_get(m, c->signals, c->n_signals, c->y, "ts", msg)) return -1;
    if (!mw_finite(m->pitch[0] + m->pitch[1] + m->pitch[2]) || !mw_finite(m->gen_speed)) {
        mw_msg(msg, "mpc-wt ts: measured pitch (records 4, 33, 34) or generator speed (20) is "
               "not finite at t = %g s", m->t);
        return -1;
    }
    if (!c->started) start(c, (m->pitch[0] + m->pitch[1] + m->pitch[2]) / 3.0);
    if (c->apc) dp = c->apc_o + c->apc_a * sin(2.0 * 3.14159265358979323846 * c->apc_f * m->t);
    clipped = outside(c->wg, c->nw, c->xi[c->n - 1]) || outside(c->rg, c->nr, dp);
    observe(c, dp);
    clipped = clipped || outside(c->wg, c->nw, c->xi[c->n - 1]);
    q = law_pdc(c, dp, raw);
    dp = dmin(dmax(dp, c->rg[0]), c->rg[c->nr - 1]);
    lo = c->limits[0];
    hi = c->limits[1];
    if (c->limits[4] >= 0.0) {     /* what the actuator can follow from the measured pitch */
        /* from the blades farthest each way: one blade that runs away or seizes must not
         * drag the others' collective command with it */
        double pmin = dmin(m->pitch[0], dmin(m->pitch[1], m->pitch[2]));
        double pmax = dmax(m->pitch[0], dmax(m->pitch[1], m->pitch[2]));
        lo = dmax(lo, pmin - c->limits[4]);
        hi = dmin(hi, pmax + c->limits[4]);
    }
    if (c->has_law)                         /* the baseline's minimum-pitch schedule */
        lo = dmax(lo, mw_torque_law_min_pitch(&c->law));
    pitch = dmin(dmax(raw[0], lo), hi);
    torque = dmin(dmax(raw[1], c->limits[2]), c->limits[3]);
    if (pitch != raw[0] || (c->own_torque && torque != raw[1])) q = c->q;   /* anti-windup */
    c->q = q;
    c->u[0] = pitch;
    c->u[1] = torque;
    if (c->has_law) {          /* the torque from the baseline's schedule, the pitch from TS */
        torque = mw_torque_law_step(&c->law, m->gen_speed, pitch, c->rated_power * (1.0 - dp));
        c->u[1] = torque;
    }
    for (b = 0; b < 3; b++) out->pitch[b] = pitch;
    out->torque = torque;
    out->nlog = 4;                  /* wind_est, premise_clipped, power_reduction, power_ref */
    out->log[0] = c->xi[c->n - 1];
    out->log[1] = clipped;
    out->log[2] = dp;
    out->log[3] = c->rated_power * (1.0 - dp);
    return 0;
}

static void ts_destroy(mw_ctrl *self)
{
    mw_ts *c = (mw_ts *)self;
    double *arrays[] = {c->wg, c->rg, c->phi, c->gam, c->x0, c->u0, c->kk, c->eq_wind,
                        c->eq_pitch, c->xi, c->xn, c->w, c->h, c->y};
    size_t i;
    for (i = 0; i < sizeof(arrays) / sizeof(arrays[0]); i++) free(arrays[i]);
    free(c->terms);
    free(c->signals);
    free(c);
}

static int read_terms(const mw_input *in, mw_ts *c, char *msg)
{
    double *t;
    int n, i;
    if (!(t = mw_getp_alloc(in, "", "terms", &n, msg))) return -1;
    if (n % 2) {
        mw_msg(msg, "mpc-wt ts: input file '%s': key 'terms' needs pairs of vertex indices, "
               "got %d values", in->path, n);
        free(t);
        return -1;
    }
    c->nt = n / 2;
    c->terms = (int *)malloc((size_t)n * sizeof(int));
    if (!c->terms) {
        mw_msg(msg, "mpc-wt ts: out of memory");
        free(t);
        return -1;
    }
    for (i = 0; i < n; i++) {
        if (t[i] != floor(t[i]) || t[i] < (i % 2 ? -1 : 0) || t[i] >= c->nv) {
            mw_msg(msg, "mpc-wt ts: input file '%s': key 'terms' value %d is %g, expected a "
                   "vertex index in [0, %d]%s", in->path, i + 1, t[i], c->nv - 1,
                   i % 2 ? " or -1" : "");
            free(t);
            return -1;
        }
        c->terms[i] = (int)t[i];
    }
    free(t);
    return 0;
}

static int ts_read(const mw_input *in, mw_ctrl *self, char *msg)
{
    mw_ts *c = (mw_ts *)self;
    double s[8];
    int i, nx;
    if (mw_get(in, "dt", &c->dt, msg) || mw_getp_vec(in, "", "sizes", s, 8, msg)
        || mw_getp_vec(in, "", "limits", c->limits, 5, msg)
        || mw_get(in, "rated_power", &c->rated_power, msg)
        || mw_signals_read(in, "signals", "ts", &c->signals, &c->n_signals, msg))
        return -1;
    for (i = 0; i < 8; i++) {
        if (s[i] != floor(s[i]) || s[i] < -1 || s[i] > 1000) {
            mw_msg(msg, "mpc-wt ts: input file '%s': key 'sizes' value %d is %g, expected a "
                   "whole number in [-1, 1000]", in->path, i + 1, s[i]);
            return -1;
        }
    }
    c->nw = (int)s[0];
    c->nr = (int)s[1];
    c->n = (int)s[2];
    c->nu = (int)s[3];
    c->ny = (int)s[4];
    c->nk = (int)s[5];
    c->ki = (int)s[6];
    c->own_torque = (int)s[7];
    c->nv = c->nw * c->nr;
    nx = c->n - 1;
    if (!(c->dt > 0) || c->nw < 1 || c->nr < 1 || nx < 1 || c->nu != 2
        || c->ny != c->n_signals || c->nk < nx || c->nk > nx + 1 || c->ki >= nx
        || (c->ki >= 0) != (c->nk == nx + 1) || c->own_torque < 0 || c->own_torque > 1) {
        mw_msg(msg, "mpc-wt ts: input file '%s': keys 'dt' (%g s, must be > 0) and 'sizes' "
               "(%g %g %g %g %g %g %g %g) are not a design of this library: wind and reduction "
               "grids >= 1, n_xi >= 2, n_u 2, n_y the %d signals, gain columns n_x [+1 with an "
               "integral], integral state < n_x or -1, own_torque 0 or 1", in->path, c->dt,
               s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7], c->n_signals);
        return -1;
    }
    if (!(c->wg = mw_getp_alloc_n(in, "", "wind_grid", c->nw, msg))
        || !(c->rg = mw_getp_alloc_n(in, "", "reduction_grid", c->nr, msg))
        || read_terms(in, c, msg)
        || !(c->phi = mw_getp_alloc_n(in, "", "phi", c->nt * c->n * c->n, msg))
        || !(c->gam = mw_getp_alloc_n(in, "", "gamma", c->nt * c->n * (c->nu + c->ny + 1), msg))
        || !(c->x0 = mw_getp_alloc_n(in, "", "x0", c->nv * nx, msg))
        || !(c->u0 = mw_getp_alloc_n(in, "", "u0", c->nv * c->nu, msg))
        || !(c->kk = mw_getp_alloc_n(in, "", "gain", c->nv * c->nu * c->nk, msg))
        || mw_get_int(in, "integral_source", -1, c->ny - 1, &c->src, msg)
        || mw_get_int(in, "torque_law", 0, 1, &c->has_law, msg))
        return -1;
    for (i = 1; i < c->nw; i++) {
        if (!(c->wg[i] > c->wg[i - 1])) {
            mw_msg(msg, "mpc-wt ts: input file '%s': key 'wind_grid' must increase (value %d is "
                   "%g after %g)", in->path, i + 1, c->wg[i], c->wg[i - 1]);
            return -1;
        }
    }
    for (i = 1; i < c->nr; i++) {
        if (!(c->rg[i] > c->rg[i - 1])) {
            mw_msg(msg, "mpc-wt ts: input file '%s': key 'reduction_grid' must increase (value "
                   "%d is %g after %g)", in->path, i + 1, c->rg[i], c->rg[i - 1]);
            return -1;
        }
    }
    /* the start's table: the vertex pitch over wind (no reduction), sorted by pitch */
    if (!(c->eq_pitch = mw_getp_alloc_n(in, "", "start_pitch", c->nw, msg))
        || !(c->eq_wind = mw_getp_alloc_n(in, "", "start_wind", c->nw, msg)))
        return -1;
    for (i = 1; i < c->nw; i++) {
        if (c->eq_pitch[i] < c->eq_pitch[i - 1]) {
            mw_msg(msg, "mpc-wt ts: input file '%s': key 'start_pitch' must not decrease (value "
                   "%d is %g after %g)", in->path, i + 1, c->eq_pitch[i], c->eq_pitch[i - 1]);
            return -1;
        }
    }
    if (c->has_law && mw_torque_law_read(in, &c->law, msg)) return -1;
    if (mw_has(in, "apc")) {        /* f [Hz], amplitude, offset of Delta P(t) */
        double a[3];
        if (mw_getp_vec(in, "", "apc", a, 3, msg)) return -1;
        if (!(a[0] >= 0 && mw_finite(a[0]) && mw_finite(a[1]) && mw_finite(a[2]))) {
            mw_msg(msg, "mpc-wt ts: input file '%s': key 'apc' needs a frequency >= 0 Hz and a "
                   "finite amplitude and offset (got %g %g %g)", in->path, a[0], a[1], a[2]);
            return -1;
        }
        c->apc = 1;
        c->apc_f = a[0];
        c->apc_a = a[1];
        c->apc_o = a[2];
    }
    c->xi = (double *)calloc((size_t)c->n, sizeof(double));
    c->xn = (double *)calloc((size_t)c->n, sizeof(double));
    c->w = (double *)calloc((size_t)(c->nu + c->ny + 1), sizeof(double));
    c->h = (double *)calloc((size_t)c->nv, sizeof(double));
    c->y = (double *)calloc((size_t)c->ny, sizeof(double));
    if (!c->xi || !c->xn || !c->w || !c->h || !c->y) {
        mw_msg(msg, "mpc-wt ts: out of memory");
        return -1;
    }
    c->base.dt = c->dt;
    return 0;
}

mw_ctrl *mw_ts_new(const mw_input *in, char *msg)
{
    return mw_ctrl_new(sizeof(mw_ts), "ts", ts_step, ts_destroy, ts_read, in, msg);
}
