/* Madsen et al.'s model predictive controller, scheduled over a model family on the wind the
 * controller estimates, as mpc-wt designs it.
 *
 * One design per grid wind: a steady-state Kalman filter for the states and the blade-effective
 * winds, and a condensed QP (prediction eq 20, Coleman-weighted cost eqs 21-22, actuator limits
 * eqs 12 and 15, soft rotor-speed limit) whose vectors are an affine map of the step's data
 * z = [1, x, u_prev, r_z, r_u, d preview] and whose linear term is shifted into the bounds
 * (v = c + v': a step only changes the bounds). DAQP solves it on a workspace set up once per
 * design. A failed QP takes the rest of the last plan (level 1) or holds the last command
 * (level 2) and is reported as a warning (aviFAIL = 1).
 *
 * The schedule (windest.c) picks the design; on a switch the new one continues from the old
 * one's last command and estimate (bumpless). The cost tracks the family's trim at the
 * low-passed estimated wind, with the torque of the baseline's schedule at the measured speed
 * and no more power than that torque gives there. */
#if !defined(_WIN32) && !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 199309L
#endif
#include "mpcwt_discon.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if !defined(_WIN32)
#include <time.h>
#endif

#include "api.h"
#include "constants.h"
#include "utils.h"

/* im's head: sizes (the layout of mpc-wt's packed step data) */
enum { NZD, SLACK0, NX, ND, NY, NB, NV, NU, NZ, HEAD };

typedef struct {
    int nx, nd, nu, ny, nb, nv, nz, nzd, nvu, hp, hu, slack0, nzo, collective;
    int *im;
    double *fc, *wt, *fb, *z_init, *su, *u0, *z0, *x0d0, *up0;
    double limits[4];
    /* DAQP */
    DAQPProblem prob;
    DAQPWorkspace work;
    DAQPResult res;
    double *h, *a, *xs, *lam;
    int *sense, work_ready;
    /* state */
    double *plan, *u_prev, *udev;
    int has_plan, has_prev, fallbacks;
    double applied_torque;        /* the torque applied over the last step (the notch's) */
    int has_applied;
    mw_kalman kal;
} mw_point;

/* the LIDAR's per-blade preview: each blade's wind from the lidar records (mw_lidar_winds), the measured mean wind
 * (the average while fewer than tau / dt samples have come, then a first-order low-pass), a
 * ring of the last measurements and the preview of the next H_p steps from the measurements
 * taken T_p = D / V_m earlier, linear in time between them */
typedef struct {
    int on, horizon, cap, n;
    double cos_cone, focus, min_wind, alpha, fixed, dt;
    int n_mean;
    double mean, last;
    double *t, *u;                /* 2 cap times, 3 x 2 cap winds (each sample twice) */
    double *blade;                /* horizon x 3 */
    double now[3];                /* the last sample's wind at each blade [m/s] */
} mw_preview;

typedef struct {
    mw_ctrl base;
    int n, collective, nzo, ip, has_law;
    mw_preview pv;
    double dt, target_tau, eff, qp_budget_ms;
    double power_limit;           /* the electrical power's ceiling [W] (0: none) */
    double *trim_z, *trim_u, *zt, ut[4];
    int *signals, n_signals;
    double *y;
    mw_point *pt;
    mw_schedule sched;
    mw_torque_law law;
    double law_lull[2];           /* the law's pitch counts in full above law_lull[1], not at
                                     all below law_lull[0] (generator speeds [rad/s]) */
    double target_wind, pitch_target_wind;
    int target_started;
    int has_notch;                /* the notch on the torque command, its largest rate */
    mw_sos notch;
    double torque_rate;
    int level;                    /* the last step's fallback (0: the QP's plan) */
    double qp_ms;                 /* the last step's QP solve time [ms] */
} mw_mpc;

static double dmin(double a, double b) { return a < b ? a : b; }
static double dmax(double a, double b) { return a > b ? a : b; }

/* ---- the LIDAR preview ---------------------------------------------------------------- */
static int preview_read(const mw_input *in, double dt, int horizon, mw_preview *p, char *msg)
{
    double v[5], longest;
    if (mw_getp_vec(in, "", "lidar", v, 5, msg)) return -1;
    p->cos_cone = v[0];
    p->focus = v[1];
    p->min_wind = v[2];
    p->fixed = v[4];
    if (!(p->cos_cone > 0 && p->cos_cone <= 1) || !(p->focus > 0) || !(p->min_wind > 0)
        || !(v[3] > 0)) {
        mw_msg(msg, "mpc-wt mpc: input file '%s': key 'lidar' needs cos(cone) in (0, 1], focus "
               "distance, minimum wind and mean time constant > 0, got %g %g %g %g", in->path,
               v[0], v[1], v[2], v[3]);
        return -1;
    }
    p->alpha = dmin(1.0, dt / v[3]);
    p->dt = dt;
    p->horizon = horizon;
    longest = p->fixed > 0 ? p->fixed : p->focus / p->min_wind;
    p->cap = (int)ceil(longest / dt) + 3;
    p->t = (double *)calloc((size_t)(2 * p->cap), sizeof(double));
    p->u = (double *)calloc((size_t)(6 * p->cap), sizeof(double));
    p->blade = (double *)calloc((size_t)(3 * horizon), sizeof(double));
    if (!p->t || !p->u || !p->blade) {
        mw_msg(msg, "mpc-wt mpc: out of memory");
        return -1;
    }
    p->on = 1;
    return 0;
}

static void preview_reset(mw_preview *p)
{
    p->n = 0;
    p->n_mean = 0;
    p->last = -1e300;
}

/* take this step's measurement and write the preview rows into p->blade; -1 on bad data */
static int preview_step(mw_preview *p, const mw_meas *m, char *msg)
{
    double u[3], x, tp, taken;
    int i, b, k, n, lo;
    if (p->n_mean == 0 && !(p->fixed > 0)) {   /* the first sample's own mean sets its lead */
        if (mw_lidar_winds(m, p->cos_cone, 0.0, u, &taken, "mpc", msg)) return -1;
        tp = p->focus / dmax((u[0] + u[1] + u[2]) / 3.0, p->min_wind);
    } else {
        tp = p->fixed > 0 ? p->fixed : p->focus / dmax(p->mean, p->min_wind);
    }
    if (mw_lidar_winds(m, p->cos_cone, tp, u, &taken, "mpc", msg)) return -1;
    if (taken > p->last) {          /* a new sample (a held one is not taken again) */
        x = (u[0] + u[1] + u[2]) / 3.0;
        p->n_mean++;
        if (p->n_mean == 1)
            p->mean = x;
        else
            p->mean += dmax(1.0 / p->n_mean, p->alpha) * (x - p->mean);
        i = p->n % p->cap;
        p->t[i] = p->t[i + p->cap] = taken;
        for (b = 0; b < 3; b++)
            p->u[b * 2 * p->cap + i] = p->u[b * 2 * p->cap + i + p->cap] = u[b];
        for (b = 0; b < 3; b++) p->now[b] = u[b];
        p->n++;
        p->last = taken;
    }
    n = p->n < p->cap ? p->n : p->cap;
    lo = p->n >= p->cap ? p->n % p->cap : 0;
    tp = p->fixed > 0 ? p->fixed : p->focus / dmax(p->mean, p->min_wind);
    for (k = 0; k < p->horizon; k++) {
        double tm = m->t + p->dt * (double)(k + 1) - tp;
        tm = dmin(tm, m->t);
        tm = dmin(dmax(tm, p->t[lo]), p->t[lo + n - 1]);
        for (b = 0; b < 3; b++)
            p->blade[k * 3 + b] = mw_interp(tm, p->t + lo, p->u + b * 2 * p->cap + lo, n);
    }
    return 0;
}

/* ---- one design ------------------------------------------------------------------------ */
static void point_free(mw_point *p)
{
    if (p->work_ready) {
        free_daqp_workspace(&p->work);
        free_daqp_ldp(&p->work);
    }
    free(p->im);
    free(p->fc);
    free(p->wt);
    free(p->fb);
    free(p->z_init);
    free(p->su);
    free(p->u0);
    free(p->z0);
    free(p->x0d0);
    free(p->up0);
    free(p->h);
    free(p->a);
    free(p->xs);
    free(p->lam);
    free(p->sense);
    free(p->plan);
    free(p->u_prev);
    free(p->udev);
    mw_kalman_free(&p->kal);
}

static void set_target(mw_point *p, const double *zt, const double *ut)
{
    double *r = p->fb + 1 + p->nx + p->nu;
    int i;
    for (i = 0; i < p->nzo; i++) r[i] = zt ? zt[i] - p->z0[i] : 0.0;
    if (!ut) {
        for (i = 0; i < p->nu; i++) r[p->nzo + i] = 0.0;
    } else if (p->collective) {
        r[p->nzo] = ((ut[0] - p->u0[0]) + (ut[1] - p->u0[1]) + (ut[2] - p->u0[2])) / 3.0;
        r[p->nzo + 1] = ut[3] - p->u0[3];
    } else {
        for (i = 0; i < 4; i++) r[p->nzo + i] = ut[i] - p->u0[i];
    }
}

static void point_reset(mw_point *p)
{
    p->has_plan = p->has_prev = p->has_applied = 0;
    p->fallbacks = 0;
    mw_kalman_reset(&p->kal);
    memcpy(p->fb, p->z_init, (size_t)p->nz * sizeof(double));
    set_target(p, NULL, NULL);
}

/* the absolute command of a deviation du (n_u) */
static void u_abs(const mw_point *p, const double *du, double *u)
{
    if (p->collective) {
        u[0] = u[1] = u[2] = p->u0[0] + du[0];
        u[3] = p->u0[3] + du[1];
    } else {
        int i;
        for (i = 0; i < 4; i++) u[i] = p->u0[i] + du[i];
    }
}

static int point_read(const mw_input *in, int k, mw_point *p, char *msg)
{
    char pre[64], sub[80];
    double s[14], *imd;
    int i, m, ms;
    snprintf(pre, sizeof(pre), "point.%d.", k);
    if (mw_getp_vec(in, pre, "sizes", s, 14, msg)) return -1;
    p->nx = (int)s[0]; p->nd = (int)s[1]; p->nu = (int)s[2]; p->ny = (int)s[3];
    p->nb = (int)s[4]; p->nv = (int)s[5]; p->nz = (int)s[6]; p->nzd = (int)s[7];
    p->nvu = (int)s[8]; p->hp = (int)s[9]; p->hu = (int)s[10]; p->slack0 = (int)s[11];
    p->nzo = (int)s[12]; p->collective = (int)s[13];
    if (p->nx < 1 || p->nd < 1 || (p->nu != 4 && p->nu != 2) || p->nb % 2 || p->nv < p->nvu
        || p->nz < p->nzd || p->nvu != p->hu * p->nu || p->nz - p->nzd != p->hp * p->nd
        || p->nzd != 1 + p->nx + 2 * p->nu + p->nzo || p->ny < p->nv) {
        mw_msg(msg, "mpc-wt mpc: input file '%s': key '%ssizes' is inconsistent", in->path,
               pre);
        return -1;
    }
    m = p->nb / 2;
    imd = mw_getp_alloc_n(in, pre, "im", HEAD + p->nx + p->nb + 4, msg);
    if (!imd) return -1;
    p->im = (int *)malloc((size_t)(HEAD + p->nx + p->nb + 4) * sizeof(int));
    if (!p->im) {
        free(imd);
        mw_msg(msg, "mpc-wt mpc: out of memory");
        return -1;
    }
    for (i = 0; i < HEAD + p->nx + p->nb + 4; i++) p->im[i] = (int)imd[i];
    free(imd);
    for (i = 0; i < p->nb; i++) {
        int r = p->im[HEAD + p->nx + i];
        if (r < 0 || r >= p->ny) {
            mw_msg(msg, "mpc-wt mpc: input file '%s': key '%sim' bound %d maps to row %d "
                   "outside [0, %d)", in->path, pre, i, r, p->ny);
            return -1;
        }
    }
    for (i = 0; i < 4; i++) {
        int c = p->im[HEAD + p->nx + p->nb + i];
        if (c < 0 || c >= p->nu) {
            mw_msg(msg, "mpc-wt mpc: input file '%s': key '%sim' command column %d outside "
                   "[0, %d)", in->path, pre, c, p->nu);
            return -1;
        }
    }
    if (!(p->fc = mw_getp_alloc_n(in, pre, "fc", p->nx + p->nd + 2 * p->nb + p->nu + 1 + 4, msg))
        || !(p->wt = mw_getp_alloc_n(in, pre, "wt", p->nz * p->ny, msg))
        || !(p->z_init = mw_getp_alloc_n(in, pre, "z_init", p->nz, msg))
        || !(p->su = mw_getp_alloc_n(in, pre, "su", p->nv, msg))
        || !(p->u0 = mw_getp_alloc_n(in, pre, "u0", 4, msg))
        || !(p->z0 = mw_getp_alloc_n(in, pre, "z0", p->nzo, msg))
        || !(p->x0d0 = mw_getp_alloc_n(in, pre, "x0d0", p->nx + p->nd, msg))
        || !(p->up0 = mw_getp_alloc_n(in, pre, "up0", p->nu, msg))
        || !(p->h = mw_getp_alloc_n(in, pre, "h", p->nv * p->nv, msg))
        || mw_getp_vec(in, pre, "limits", p->limits, 4, msg))
        return -1;
    if (mw_getp_int(in, pre, "n_box", 0, m, &ms, msg)) return -1;
    if (!(p->a = mw_getp_alloc_n(in, pre, "a", (m - ms) * p->nv, msg))) return -1;
    snprintf(sub, sizeof(sub), "%skalman.", pre);
    if (mw_kalman_read(in, sub, 4, &p->kal, msg)) return -1;
    if (p->kal.n != p->nx + p->nd) {
        mw_msg(msg, "mpc-wt mpc: input file '%s': the Kalman filter of '%s' has %d states, "
               "the design %d", in->path, pre, p->kal.n, p->nx + p->nd);
        return -1;
    }
    p->fb = (double *)calloc((size_t)(p->nz + p->ny + p->nb + p->nv + 4 + p->nu + 1),
                             sizeof(double));
    p->xs = (double *)calloc((size_t)p->nv, sizeof(double));
    p->lam = (double *)calloc((size_t)m, sizeof(double));
    p->sense = (int *)calloc((size_t)m, sizeof(int));
    p->plan = (double *)calloc((size_t)p->nvu, sizeof(double));
    p->u_prev = (double *)calloc((size_t)p->nu, sizeof(double));
    p->udev = (double *)calloc(4, sizeof(double));
    if (!p->fb || !p->xs || !p->lam || !p->sense || !p->plan || !p->u_prev || !p->udev) {
        mw_msg(msg, "mpc-wt mpc: out of memory");
        return -1;
    }
    /* the QP: min 0.5 v'Hv, lo <= v <= hi (ms box rows), lo <= A v <= hi; bounds in fb */
    {
        double *lo = p->fb + p->nz + p->ny, *hi = lo + m;
        int flag;
        for (i = 0; i < m; i++) {
            lo[i] = -1e30;
            hi[i] = 1e30;
        }
        memset(&p->prob, 0, sizeof(p->prob));
        p->prob.n = p->nv;
        p->prob.m = m;
        p->prob.ms = ms;
        p->prob.H = p->h;
        p->prob.f = NULL;
        p->prob.A = p->a;
        p->prob.bupper = hi;
        p->prob.blower = lo;
        p->prob.sense = p->sense;
        memset(&p->work, 0, sizeof(p->work));
        allocate_daqp_settings(&p->work);
        flag = setup_daqp(&p->prob, &p->work, NULL);
        p->work_ready = 1;
        if (flag < 0) {
            mw_msg(msg, "mpc-wt mpc: input file '%s': the QP of '%s' does not set up in DAQP "
                   "(exit flag %d: H not positive definite?)", in->path, pre, flag);
            return -1;
        }
        memset(&p->res, 0, sizeof(p->res));
        p->res.x = p->xs;
        p->res.lam = p->lam;
    }
    point_reset(p);
    return 0;
}

/* the step's QP vectors from z (mpc-wt's _step_map without state or blade preview) */
static void step_map(mw_point *p, const double *up)
{
    const int *im = p->im;
    int nx = p->nx, nd = p->nd, ny = p->ny, nb = p->nb, nz = p->nz, i, j, r;
    double *z = p->fb, *y = p->fb + nz;
    const double *fc = p->fc;
    for (i = 0; i < p->nu; i++) z[1 + nx + i] = up[i];
    for (i = 0; i < ny; i++) y[i] = 0.0;
    for (j = 0; j < nz; j++) {
        double zj = z[j];
        if (zj != 0.0) {
            const double *row = p->wt + (size_t)j * ny;
            for (i = 0; i < ny; i++) y[i] += row[i] * zj;
        }
    }
    for (r = 0; r < nb; r++) {
        int c0 = nx + nd;
        p->fb[nz + ny + r] = fc[c0 + r] + fc[c0 + nb + r] * y[im[HEAD + nx + r]];
    }
}

/* v = xs + c, the first command's deviation and absolute value; 0 when v is not finite */
static int step_result(mw_point *p)
{
    int nx = p->nx, nd = p->nd, ny = p->ny, nb = p->nb, nv = p->nv, nu = p->nu, nz = p->nz;
    int iv = nz + ny + nb, isu = nx + nd + 2 * nb, iu = iv + nv, idu = iv + nv + 4, k, i;
    double total = 0.0;
    double *fb = p->fb;
    const double *fc = p->fc;
    for (i = 0; i < nv; i++) {
        fb[iv + i] = p->xs[i] + fb[nz + i];
        total += fb[iv + i];
    }
    if (!mw_finite(total)) return 0;
    for (k = 0; k < nu; k++) fb[idu + k] = fb[iv + k] * fc[isu + k];
    for (k = 0; k < 4; k++)
        fb[iu + k] = fc[isu + nu + 1 + k] + fb[idu + p->im[HEAD + nx + nb + k]];
    return 1;
}

static double now_ms(void)
{
#if !defined(_WIN32)
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
#else
    return 0.0;
#endif
}

/* one step of a design: estimate, QP, fallback; 0, 1 (a fallback, msg says why) or -1 */
static int point_step(mw_mpc *c, mw_point *p, const mw_meas *m, double *u, char *msg)
{
    int nx = p->nx, nu = p->nu, i, flag, level = 0;
    double *z = p->fb, t0, ms;
    if (mw_signals_get(m, c->signals, c->n_signals, c->y, "mpc", msg)) return -1;
    if (p->has_prev) {
        u_abs(p, p->u_prev, p->udev);
        for (i = 0; i < 4; i++) p->udev[i] -= p->u0[i];
    } else {
        for (i = 0; i < 4; i++) p->udev[i] = 0.0;
    }
    if (p->has_applied) p->udev[3] = p->applied_torque - p->u0[3];
    mw_kalman_update(&p->kal, c->y, p->udev);
    for (i = 0; i < nx; i++) z[1 + i] = p->kal.xa[i];
    if (c->pv.on) {                     /* the LIDAR's per-blade preview, as deviations */
        const double *fc = p->fc;
        int r, j, rows = c->pv.horizon;
        for (i = 0; i < p->hp; i++) {
            r = i < rows - 1 ? i : rows - 1;
            if (p->nd == 3) {
                for (j = 0; j < 3; j++)
                    z[p->nzd + i * 3 + j] = c->pv.blade[r * 3 + j] - fc[nx + j];
            } else {
                double acc = 0.0;
                for (j = 0; j < 3; j++) acc += c->pv.blade[r * 3 + j];
                z[p->nzd + i] = acc / 3.0 - fc[nx];
            }
        }
    } else {
        for (i = 0; i < p->hp * p->nd; i++) z[p->nzd + i] = p->kal.xa[nx + i % p->nd];
    }
    t0 = now_ms();
    step_map(p, p->has_prev ? p->u_prev : p->up0);
    flag = daqp_update_ldp(DAQP_UPDATE_d, &p->work, &p->prob);
    if (flag >= 0) {
        daqp_solve(&p->res, &p->work);
        flag = p->res.exitflag;
        if (flag == 1 && !step_result(p)) flag = 0;
    }
    ms = now_ms() - t0;
    c->qp_ms = ms;
    if (flag == 1 && c->qp_budget_ms > 0 && ms > c->qp_budget_ms) flag = -100;
    if (flag == 1) {
        int iv = p->nz + p->ny + p->nb;
        memcpy(p->plan, p->fb + iv, (size_t)p->nvu * sizeof(double));
        memcpy(p->u_prev, p->fb + iv + p->nv + 4, (size_t)nu * sizeof(double));
        memcpy(u, p->fb + iv + p->nv, 4 * sizeof(double));
        p->has_plan = p->has_prev = 1;
    } else {
        /* the rest of the last plan (1), or the last command held (2) */
        if (p->has_plan && p->nvu > nu) {
            memmove(p->plan, p->plan + nu, (size_t)(p->nvu - nu) * sizeof(double));
            /* the last move is repeated: plan[-nu:] of the shifted plan */
            level = 1;
        } else {
            for (i = 0; i < p->nvu; i++)
                p->plan[i] = p->has_prev ? p->u_prev[i % nu] / p->su[i % nu] : 0.0;
            level = 2;
        }
        p->has_plan = 1;
        for (i = 0; i < nu; i++) p->u_prev[i] = p->plan[i] * p->su[i];
        p->has_prev = 1;
        u_abs(p, p->u_prev, u);
        p->fallbacks++;
        if (flag == -100)
            mw_msg(msg, "mpc-wt mpc: the QP took %.3g ms, over its budget of %g ms at t = %g s: "
                   "fallback %d (%d so far)", ms, c->qp_budget_ms, m->t, level, p->fallbacks);
        else
            mw_msg(msg, "mpc-wt mpc: QP not solved (DAQP exit flag %d) at t = %g s: fallback "
                   "%d (%d so far)", flag, m->t, level, p->fallbacks);
    }
    for (i = 0; i < 3; i++) u[i] = dmin(dmax(u[i], p->limits[0]), p->limits[1]);
    u[3] = dmin(dmax(u[3], p->limits[2]), p->limits[3]);
    c->level = level;
    return level ? 1 : 0;
}

/* continue from another design's last command and estimate, in absolute units */
static void hand_over(mw_point *to, const mw_point *from)
{
    int i;
    if (from->has_prev) {
        double u[4];
        u_abs(from, from->u_prev, u);
        for (i = 0; i < 4; i++) u[i] -= to->u0[i];
        if (to->collective) {
            to->u_prev[0] = u[0];
            to->u_prev[1] = u[3];
        } else {
            for (i = 0; i < 4; i++) to->u_prev[i] = u[i];
        }
        to->has_prev = 1;
    }
    to->applied_torque = from->applied_torque;
    to->has_applied = from->has_applied;
    for (i = 0; i < to->kal.n; i++)
        to->kal.xa[i] = from->kal.xa[i] + (from->x0d0[i] - to->x0d0[i]);
    to->kal.started = from->kal.started;
}

/* ---- the scheduled controller ------------------------------------------------------------ */
static void trim_at(const mw_mpc *c, double wind, double *z, double *u)
{
    const double *g = c->sched.grid;
    int n = c->n, i = 0, j;
    double a;
    if (n == 1) {
        if (z) memcpy(z, c->trim_z, (size_t)c->nzo * sizeof(double));
        memcpy(u, c->trim_u, 4 * sizeof(double));
        return;
    }
    while (i < n && g[i] <= wind) i++;             /* bisect_right */
    i = i - 1;
    if (i < 0) i = 0;
    if (i > n - 2) i = n - 2;
    a = dmin(dmax((wind - g[i]) / (g[i + 1] - g[i]), 0.0), 1.0);
    for (j = 0; z && j < c->nzo; j++)              /* z NULL: the inputs only */
        z[j] = (1.0 - a) * c->trim_z[i * c->nzo + j] + a * c->trim_z[(i + 1) * c->nzo + j];
    for (j = 0; j < 4; j++)
        u[j] = (1.0 - a) * c->trim_u[i * 4 + j] + a * c->trim_u[(i + 1) * 4 + j];
}

static int mpc_step(mw_ctrl *self, const mw_meas *m, mw_cmd *out, char *msg)
{
    mw_mpc *c = (mw_mpc *)self;
    int switched, k, rc, i, before = c->sched.active;    /* the design acting until now */
    double u[4];
    if (!mw_finite(m->rotor_speed) || !mw_finite(m->gen_torque)
        || !mw_finite(m->pitch[0] + m->pitch[1] + m->pitch[2]) || !mw_finite(m->gen_speed)) {
        mw_msg(msg, "mpc-wt mpc: measured rotor speed (record 21), generator speed (20), "
               "torque (23) or pitch (4, 33, 34) is not finite at t = %g s", m->t);
        return -1;
    }
    if (c->pv.on) {
        if (preview_step(&c->pv, m, msg)) return -1;
        k = mw_schedule_update_wind(&c->sched,
                                    (c->pv.blade[0] + c->pv.blade[1] + c->pv.blade[2]) / 3.0,
                                    m, &switched);
    } else {
        k = mw_schedule_update(&c->sched, m, &switched);
    }
    if (switched) {
        point_reset(&c->pt[k]);
        hand_over(&c->pt[k], &c->pt[before]);
    }
    if (c->target_tau >= 0.0) {
        /* speed, power and torque from the floored wind, the pitch from the wind itself */
        double w = c->sched.floored, wp = c->sched.measured;
        if (!c->target_started) {
            c->target_wind = w;
            c->pitch_target_wind = wp;
            c->target_started = 1;
        } else {
            double a = c->target_tau == 0.0 ? 1.0 : dmin(1.0, c->dt / c->target_tau);
            c->target_wind += a * (w - c->target_wind);
            c->pitch_target_wind += a * (wp - c->pitch_target_wind);
        }
        trim_at(c, c->target_wind, c->zt, c->ut);
        if (c->pitch_target_wind != c->target_wind) {
            double up[4];
            trim_at(c, c->pitch_target_wind, NULL, up);
            for (i = 0; i < 3; i++) c->ut[i] = up[i];
        }
        if (c->has_law) {
            double w_g = m->gen_speed, pitch = (m->pitch[0] + m->pitch[1] + m->pitch[2]) / 3.0;
            double q = mw_torque_law_step(&c->law, w_g, pitch, c->law.law.p_rated);
            /* a pitched rotor well below rated speed is in a lull, not in region 3: the
             * target there is the law's region-2 torque, not rated power's, reached linearly
             * in the filtered speed between the two lull speeds (no step in the target) */
            double a = (c->law.w - c->law_lull[0]) / (c->law_lull[1] - c->law_lull[0]);
            if (a < 1.0) {
                double q2 = mw_law_torque(&c->law.law, c->law.w, c->law.law.p_min,
                                          c->law.law.p_rated);
                q2 = dmin(dmax(q2, c->law.lo), c->law.hi);
                a = dmax(a, 0.0);
                q = a * q + (1.0 - a) * q2;
            }
            c->ut[3] = q;
            c->zt[c->ip] = dmin(c->zt[c->ip], c->eff * q * w_g);
        }
        set_target(&c->pt[k], c->zt, c->ut);
    }
    rc = point_step(c, &c->pt[k], m, u, msg);
    if (rc < 0) return rc;
    if (c->has_notch || c->power_limit > 0.0) {
        /* within the torque limits, the power ceiling and the generator's rate */
        mw_point *p = &c->pt[k];
        double q = u[3];
        if (c->has_notch) {
            mw_sos_step(&c->notch, &u[3], &q);
            q = dmin(dmax(q, p->limits[2]), p->limits[3]);
        }
        if (c->power_limit > 0.0 && m->gen_speed > 0.0)
            q = dmin(q, c->power_limit / (c->eff * m->gen_speed));
        if (p->has_applied)         /* the last applied torque (handed over on a switch) */
            q = dmin(dmax(q, p->applied_torque - c->torque_rate * c->dt),
                     p->applied_torque + c->torque_rate * c->dt);
        u[3] = p->applied_torque = q;
        p->has_applied = 1;
    }
    for (i = 0; i < 3; i++) out->pitch[i] = u[i];
    out->torque = u[3];
    out->nlog = 4;                  /* qp_fallback, qp_solve_ms, schedule_wind, its grid wind */
    out->log[0] = c->level;
    out->log[1] = c->qp_ms;
    out->log[2] = c->sched.wind;
    out->log[3] = c->sched.grid[k];
    if (c->pv.on) {                 /* lidar_wind_1..3: the last sample's wind at each blade */
        out->nlog = 7;
        for (i = 0; i < 3; i++) out->log[4 + i] = c->pv.now[i];
    }
    {                               /* wind_est_1..3: the Kalman filter's blade winds [m/s] */
        const mw_point *p = &c->pt[k];
        for (i = 0; i < 3; i++) {
            int j = p->nd == 3 ? i : 0;
            out->log[out->nlog + i] = p->kal.xa[p->nx + j] + p->x0d0[p->nx + j];
        }
        out->nlog += 3;
    }
    out->log[out->nlog] = mw_schedule_outside(&c->sched);   /* schedule_outside */
    out->log[out->nlog + 1] = mw_schedule_estimator_outside(&c->sched); /* estimator_outside */
    out->nlog += 2;
    return rc;
}

static void mpc_destroy(mw_ctrl *self)
{
    mw_mpc *c = (mw_mpc *)self;
    int i;
    if (c->pt)
        for (i = 0; i < c->n; i++) point_free(&c->pt[i]);
    free(c->pt);
    free(c->trim_z);
    free(c->trim_u);
    free(c->zt);
    free(c->signals);
    free(c->y);
    free(c->pv.t);
    free(c->pv.u);
    free(c->pv.blade);
    mw_sos_free(&c->notch);
    mw_schedule_free(&c->sched);
    free(c);
}

static int read_signals(const mw_input *in, mw_mpc *c, char *msg)
{
    if (mw_signals_read(in, "kalman_signals", "mpc", &c->signals, &c->n_signals, msg))
        return -1;
    c->y = (double *)malloc((size_t)c->n_signals * sizeof(double));
    if (!c->y) {
        mw_msg(msg, "mpc-wt mpc: out of memory");
        return -1;
    }
    return 0;
}

static int mpc_read(const mw_input *in, mw_ctrl *self, char *msg)
{
    mw_mpc *c = (mw_mpc *)self;
    int i;
    if (mw_get(in, "dt", &c->dt, msg) || mw_get_int(in, "n_points", 1, 1000, &c->n, msg)
        || mw_get_int(in, "n_outputs", 1, 1000, &c->nzo, msg)
        || mw_get_int(in, "power_output", 0, c->nzo - 1, &c->ip, msg)
        || mw_get(in, "power_efficiency", &c->eff, msg)
        || mw_get(in, "target_time_constant", &c->target_tau, msg)
        || mw_get(in, "qp_time_budget_ms", &c->qp_budget_ms, msg)
        || mw_get_int(in, "torque_law", 0, 1, &c->has_law, msg) || read_signals(in, c, msg))
        return -1;
    if (!(c->dt > 0)) {
        mw_msg(msg, "mpc-wt mpc: input file '%s': key 'dt' must be > 0 s, got %g", in->path,
               c->dt);
        return -1;
    }
    if (mw_schedule_read(in, "schedule.", c->dt, &c->sched, msg)) return -1;
    {
        int lidar;
        if (mw_get_int(in, "lidar_preview", 0, 1, &lidar, msg)) return -1;
        if (lidar) {
            int hp;
            if (mw_get_int(in, "lidar_horizon", 1, 10000, &hp, msg)
                || preview_read(in, c->dt, hp, &c->pv, msg))
                return -1;
            preview_reset(&c->pv);
        }
    }
    if (c->sched.n != c->n) {
        mw_msg(msg, "mpc-wt mpc: input file '%s': key 'schedule.grid' has %d winds, "
               "n_points is %d", in->path, c->sched.n, c->n);
        return -1;
    }
    if (!(c->trim_z = mw_getp_alloc_n(in, "", "trim_z", c->n * c->nzo, msg))
        || !(c->trim_u = mw_getp_alloc_n(in, "", "trim_u", c->n * 4, msg)))
        return -1;
    c->zt = (double *)calloc((size_t)c->nzo, sizeof(double));
    c->pt = (mw_point *)calloc((size_t)c->n, sizeof(mw_point));
    if (!c->zt || !c->pt) {
        mw_msg(msg, "mpc-wt mpc: out of memory");
        return -1;
    }
    if (c->has_law) {
        if (mw_torque_law_read(in, &c->law, msg)
            || mw_getp_vec(in, "", "law_lull_speeds", c->law_lull, 2, msg))
            return -1;
        if (!mw_finite(c->law_lull[0]) || !mw_finite(c->law_lull[1]) || !(c->law_lull[0] >= 0.0)
            || !(c->law_lull[1] > c->law_lull[0])) {
            mw_msg(msg, "mpc-wt mpc: input file '%s': key 'law_lull_speeds' must be two finite "
                   "generator speeds, 0 <= first < second [rad/s], got %g %g", in->path,
                   c->law_lull[0], c->law_lull[1]);
            return -1;
        }
    }
    if (mw_get_int(in, "torque_notch", 0, 1, &c->has_notch, msg)
        || mw_get(in, "power_limit", &c->power_limit, msg))
        return -1;
    if (!(c->power_limit >= 0.0)) {
        mw_msg(msg, "mpc-wt mpc: input file '%s': key 'power_limit' must be >= 0 W (0: none), "
               "got %g", in->path, c->power_limit);
        return -1;
    }
    if (c->has_notch
        && mw_sos_read(in, "mpc", "torque_notch_sos", "torque_notch_zi", 1, &c->notch, msg))
        return -1;
    if (c->has_notch || c->power_limit > 0.0) {
        if (mw_get(in, "torque_notch_rate", &c->torque_rate, msg)) return -1;
        if (!(c->torque_rate > 0)) {
            mw_msg(msg, "mpc-wt mpc: input file '%s': key 'torque_notch_rate' must be > 0 N m/s, "
                   "got %g", in->path, c->torque_rate);
            return -1;
        }
    }
    for (i = 0; i < c->n; i++) {
        if (point_read(in, i, &c->pt[i], msg)) return -1;
        if (c->pt[i].nzo != c->nzo) {
            mw_msg(msg, "mpc-wt mpc: input file '%s': point %d has %d outputs, n_outputs is %d",
                   in->path, i, c->pt[i].nzo, c->nzo);
            return -1;
        }
        if (c->pv.on && c->pt[i].hp > c->pv.horizon) {
            mw_msg(msg, "mpc-wt mpc: input file '%s': point %d's horizon %d is longer than the "
                   "LIDAR preview's %d", in->path, i, c->pt[i].hp, c->pv.horizon);
            return -1;
        }
        if (c->pt[i].kal.ny != c->n_signals) {
            mw_msg(msg, "mpc-wt mpc: input file '%s': point %d's Kalman filter measures %d "
                   "signals, kalman_signals lists %d", in->path, i, c->pt[i].kal.ny,
                   c->n_signals);
            return -1;
        }
    }
    c->base.dt = c->dt;
    return 0;
}

mw_ctrl *mw_mpc_new(const mw_input *in, char *msg)
{
    return mw_ctrl_new(sizeof(mw_mpc), "mpc", mpc_step, mpc_destroy, mpc_read, in, msg);
}
