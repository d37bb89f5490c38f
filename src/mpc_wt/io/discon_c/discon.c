/* The Bladed-style entry point as OpenFAST's ServoDyn (and Bladed) call it:
 *
 *   DISCON(avrSWAP, aviFAIL, accINFILE, avcOUTNAME, avcMSG)
 *
 * avrSWAP(1) is the status: 0 at the first call (read the input file, make the controller,
 * then step), 1 at every later one (step), -1 at the last (free). Errors set aviFAIL = -1 and
 * a message in avcMSG (its length in avrSWAP(49)); the caller stops the run. A warning (the
 * MPC's fallback when its QP fails) sets aviFAIL = 1 with its message; the demands apply.
 *
 * One instance per simulation root name (avcOUTNAME, up to MW_MAX_INSTANCES): two turbines
 * that load one copy of the library keep their own state. */
#include "mpcwt_discon.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(_WIN32)
#define MW_EXPORT __declspec(dllexport)
#else
#define MW_EXPORT __attribute__((visibility("default")))
#endif

#if !defined(_WIN32)
#include <pthread.h>
static pthread_mutex_t mw_lock = PTHREAD_MUTEX_INITIALIZER;
#define MW_LOCK() pthread_mutex_lock(&mw_lock)
#define MW_UNLOCK() pthread_mutex_unlock(&mw_lock)
#else
#define MW_LOCK()
#define MW_UNLOCK()
#endif

#define MW_MAX_INSTANCES 64
#define MW_KEY_LEN 1024

typedef struct {
    char key[MW_KEY_LEN];     /* the root name */
    mw_ctrl *ctrl;
    double t0;                /* the first call's time [s] */
    long calls;               /* calls since the first */
} mw_instance;

static mw_instance mw_table[MW_MAX_INSTANCES];

static size_t swap_len(const float *swap, int record, size_t fallback)
{
    float v = swap[record - 1];
    if (!(v > 0) || v > 1e7) return fallback;
    return (size_t)v;
}

static void copy_msg(char *dst, size_t n, const char *src)
{
    size_t k;
    if (!dst || n == 0) return;
    k = strlen(src);
    if (k >= n) k = n - 1;
    memcpy(dst, src, k);
    dst[k] = '\0';
}

/* the root name as a NUL-terminated key */
static void root_key(const char *outname, size_t n, char *key)
{
    size_t k = 0;
    if (outname)
        while (k < n && k < MW_KEY_LEN - 1 && outname[k]) k++;
    if (k) memcpy(key, outname, k);
    key[k] = '\0';
}

static mw_instance *lookup(const char *key)
{
    int i;
    for (i = 0; i < MW_MAX_INSTANCES; i++)
        if (mw_table[i].ctrl && strcmp(mw_table[i].key, key) == 0) return &mw_table[i];
    return NULL;
}

/* the laws this library holds (mw_laws.h) and their constructors */
#define MW_LAW_ENTRY(law) {#law, mw_##law##_new},
static const struct {
    const char *name;
    mw_ctrl *(*make)(const mw_input *in, char *msg);
} laws[] = {MW_LAWS(MW_LAW_ENTRY)};
#undef MW_LAW_ENTRY
static const int n_laws = (int)(sizeof(laws) / sizeof(laws[0]));

static mw_ctrl *create(const char *path, const float *swap, char *msg)
{
    mw_input in;
    mw_ctrl *c = NULL;
    char kind[64];
    int version, i;
    double dt_call;
    if (mw_input_read(&in, path, msg)) return NULL;
    if (mw_get_int(&in, "format_version", 1, 1, &version, msg)
        || mw_get_word(&in, "kind", kind, sizeof(kind), msg)) {
        mw_input_free(&in);
        return NULL;
    }
    for (i = 0; i < n_laws; i++)
        if (strcmp(kind, laws[i].name) == 0) {
            c = laws[i].make(&in, msg);
            break;
        }
    if (i == n_laws) {
        char held[256] = "";
        for (i = 0; i < n_laws; i++) {
            if (i) strncat(held, ", ", sizeof(held) - strlen(held) - 1);
            strncat(held, laws[i].name, sizeof(held) - strlen(held) - 1);
        }
        mw_msg(msg, "mpc-wt controller: input file '%s': kind '%s' is not a law this library "
               "holds (%s); export a controller of that kind to build its library", path, kind,
               held);
    }
    mw_input_free(&in);
    if (!c) return NULL;
    dt_call = swap[2];
    if (!(fabs(dt_call - c->dt) <= 1e-6 * c->dt + 1e-7)) {
        mw_msg(msg, "mpc-wt controller: input file '%s': key 'dt' is %g s, but the library is "
               "called every %g s (avrSWAP record 3); set DLL_DT = %g in ServoDyn", path, c->dt,
               dt_call, c->dt);
        c->destroy(c);
        return NULL;
    }
    return c;
}

static void read_meas(const float *s, mw_meas *m)
{
    m->t = s[1];
    m->dt = s[2];
    m->pitch[0] = s[3];
    m->pitch[1] = s[32];
    m->pitch[2] = s[33];
    m->gen_power = s[14];
    m->gen_speed = s[19];
    m->rotor_speed = s[20];
    m->gen_torque = s[22];
    m->flap[0] = s[29];
    m->flap[1] = s[30];
    m->flap[2] = s[31];
    m->tower_fa_acc = s[52];
    m->tower_ss_acc = s[53];
    m->azimuth = s[59];
    m->lidar_type = m->lidar_beams = m->lidar_gates = m->lidar_n = 0;
    if (s[128] >= 2004.0f) {        /* record 129: the array's length; the lidar block fits */
        int n, i;
        m->lidar_type = (int)s[2000];
        m->lidar_beams = (int)s[2001];
        m->lidar_gates = (int)s[2002];
        n = m->lidar_beams * m->lidar_gates;
        if (m->lidar_beams >= 0 && m->lidar_gates >= 0 && n <= MW_LIDAR_MAX
            && 2004 + 4 * n <= (int)s[128]) {
            m->lidar_n = n;
            for (i = 0; i < n; i++) {
                m->lidar_speed[i] = s[2004 + i];
                m->lidar_y[i] = s[2004 + 2 * n + i];
                m->lidar_z[i] = s[2004 + 3 * n + i];
            }
        } else {
            m->lidar_n = -1;          /* more than a law reads, or past the array's end */
        }
    }
}

/* the wind at the rotor's sample points, fitted as u(psi) = a0 + a1 cos(psi) + b1 sin(psi)
 * over the points' azimuths about their centroid (psi from up toward -y, OpenFAST's and the
 * rotor's sense); 0 when the points do not span the rotor (fewer than 3, or on one line) */
static int fit_1p(const mw_meas *m, double c[3])
{
    double yc = 0.0, zc = 0.0, a[3][3] = {{0}}, r[3] = {0}, det;
    int i, j, k, n = m->lidar_n;
    if (n < 3) return 0;
    for (i = 0; i < n; i++) {
        yc += m->lidar_y[i] / n;
        zc += m->lidar_z[i] / n;
    }
    for (i = 0; i < n; i++) {
        double dy = m->lidar_y[i] - yc, dz = m->lidar_z[i] - zc, rad = sqrt(dy * dy + dz * dz);
        double f[3];
        if (!(rad > 1e-3)) return 0;
        f[0] = 1.0;
        f[1] = dz / rad;              /* cos(psi) */
        f[2] = -dy / rad;             /* sin(psi) */
        for (j = 0; j < 3; j++) {
            r[j] += f[j] * m->lidar_speed[i];
            for (k = 0; k < 3; k++) a[j][k] += f[j] * f[k];
        }
    }
    det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
        - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    if (!(fabs(det) > 1e-6 * n * n * n)) return 0;
    for (j = 0; j < 3; j++) {           /* Cramer's rule, column j replaced by r */
        double b[3][3];
        memcpy(b, a, sizeof(b));
        for (k = 0; k < 3; k++) b[k][j] = r[k];
        c[j] = (b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1])
                - b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0])
                + b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0])) / det;
    }
    return 1;
}

/* Each blade's wind from the lidar records, by the configuration the records describe:
 * - type 2, 3 beams, 1 gate: mpc-wt's hub-mounted CW lidar, one beam ahead of each blade,
 *   line-of-sight speeds: u = v_LOS / cos(cone);
 * - type 1 (InflowWind's single points, fixed in space), 1-5 beams: the speeds are the wind's
 *   magnitude at the points; with 3 or more around the rotor, their 1P fit at the azimuth
 *   each blade will have when the measured wind reaches it (blade k at record 60's azimuth +
 *   (k - 1) 120 deg, turned on at the rotor speed over lead_s, the preview time, less the
 *   sample's age), else their mean for every blade;
 * - type 2 or 3 with one beam (InflowWind's CW or pulsed lidar, LidRadialVel false: the
 *   speed is its estimate of the wind along x): gate 1's speed for every blade.
 * mpc-wt's host hands a sample over at the call it is taken; OpenFAST v5.0.0 at the call after
 * (its records at t are InflowWind's at t - DLL_DT, at the first call its first), so an
 * InflowWind lidar's sample is taken one interval (record 3) before the call. */
int mw_lidar_winds(const mw_meas *m, double cos_cone, double lead_s, double u[3],
                   double *taken, const char *who, char *msg)
{
    int i, b, n = m->lidar_n;
    double c[3];
    *taken = m->t;
    for (i = 0; i < n; i++)
        if (!mw_finite(m->lidar_speed[i])) {
            mw_msg(msg, "mpc-wt %s: lidar speed %d (avrSWAP %d) is not finite at t = %g s",
                   who, i + 1, 2005 + i, m->t);
            return -1;
        }
    if (m->lidar_type == 2 && m->lidar_beams == 3 && m->lidar_gates == 1 && n == 3) {
        for (b = 0; b < 3; b++) u[b] = m->lidar_speed[b] / cos_cone;
        return 0;
    }
    if (m->t > 0.0 && m->dt > 0.0) *taken = m->t - m->dt;
    if (m->lidar_type == 1 && n >= 1) {
        if (fit_1p(m, c)) {
            /* where blade b will be when the measured wind reaches the rotor, as mpc-wt's CW
             * beams lead their blades by the rotor's turn over the preview time */
            double ahead = m->rotor_speed * (lead_s - (m->t - *taken));
            for (b = 0; b < 3; b++) {
                double psi = m->azimuth + ahead + 2.0943951023931957 * b;
                u[b] = c[0] + c[1] * cos(psi) + c[2] * sin(psi);
            }
        } else {
            double s = 0.0;
            for (i = 0; i < n; i++) s += m->lidar_speed[i] / n;
            u[0] = u[1] = u[2] = s;
        }
        return 0;
    }
    if ((m->lidar_type == 2 || m->lidar_type == 3) && m->lidar_beams == 1 && n >= 1) {
        u[0] = u[1] = u[2] = m->lidar_speed[0];
        return 0;
    }
    mw_msg(msg, "mpc-wt %s: the lidar records (avrSWAP 2001-2003: type %d, %d beams, %d pulse "
           "gates) are no lidar it reads: mpc-wt's CW lidar (type 2, 3 beams, 1 gate), "
           "InflowWind's single points (type 1, 1-5 beams) or one CW or pulsed beam (type 2 or 3, "
           "1 beam); t = %g s", who, m->lidar_type, m->lidar_beams, m->lidar_gates, m->t);
    return -1;
}

/* the kind's logging channels at records L1 = record 63 on, their number in record 65, as
 * far as the host has room for them (record 62, and the swap array's length in record 129) */
static void write_log(float *s, const mw_cmd *c)
{
    int room = (int)s[61], first = (int)s[62], len = (int)s[128], n = c->nlog, i;
    if (n > room) n = room;
    if (n < 0 || first < 130 || first - 1 + n > len) n = 0;  /* no room the host offers */
    for (i = 0; i < n; i++) s[first - 1 + i] = (float)c->log[i];
    s[64] = (float)n;
}

static void write_cmd(float *s, const mw_cmd *c)
{
    s[34] = 1.0f;                     /* 35: generator contactor on */
    s[35] = 0.0f;                     /* 36: shaft brake off */
    s[40] = 0.0f;                     /* 41: yaw actuator torque demand */
    s[41] = (float)c->pitch[0];       /* 42-44: individual pitch demands [rad] */
    s[42] = (float)c->pitch[1];
    s[43] = (float)c->pitch[2];
    s[44] = (float)((c->pitch[0] + c->pitch[1] + c->pitch[2]) / 3.0); /* 45: collective */
    s[46] = (float)c->torque;         /* 47: generator torque demand [N m] */
    s[47] = 0.0f;                     /* 48: yaw rate demand */
    s[54] = 0.0f;                     /* 55: pitch override off */
    s[55] = 0.0f;                     /* 56: torque override off */
    write_log(s, c);                  /* 65 and L1 on: the logging channels */
}

MW_EXPORT void DISCON(float *avrSWAP, int *aviFAIL, const char *accINFILE, char *avcOUTNAME,
                      char *avcMSG)
{
    char msg[MW_MSG_LEN], key[MW_KEY_LEN], path[1024];
    size_t msg_len = swap_len(avrSWAP, 49, 1024);
    int status = (int)floorf(avrSWAP[0] + 0.5f);
    mw_instance *inst;
    mw_meas m;
    mw_cmd cmd;
    int rc;
    msg[0] = '\0';
    *aviFAIL = 0;
    root_key(avcOUTNAME, swap_len(avrSWAP, 51, MW_KEY_LEN), key);
    MW_LOCK();
    inst = lookup(key);
    if (status == 0) {
        size_t n = swap_len(avrSWAP, 50, sizeof(path));
        mw_ctrl *c;
        int i;
        if (n > sizeof(path)) n = sizeof(path);
        root_key(accINFILE, n, path);
        if (inst) {                                 /* a new run under the same name */
            inst->ctrl->destroy(inst->ctrl);
            inst->ctrl = NULL;
        }
        c = create(path, avrSWAP, msg);
        if (!c) {
            MW_UNLOCK();
            *aviFAIL = -1;
            copy_msg(avcMSG, msg_len, msg);
            return;
        }
        inst = NULL;
        for (i = 0; i < MW_MAX_INSTANCES; i++)
            if (!mw_table[i].ctrl) {
                inst = &mw_table[i];
                break;
            }
        if (!inst) {
            c->destroy(c);
            MW_UNLOCK();
            *aviFAIL = -1;
            mw_msg(msg, "mpc-wt controller: more than %d turbines in one process",
                   MW_MAX_INSTANCES);
            copy_msg(avcMSG, msg_len, msg);
            return;
        }
        memcpy(inst->key, key, sizeof(key));
        inst->ctrl = c;
        inst->t0 = avrSWAP[1];
        inst->calls = 0;
    }
    MW_UNLOCK();
    if (status < 0) {                               /* the last call */
        if (inst) {
            MW_LOCK();
            inst->ctrl->destroy(inst->ctrl);
            inst->ctrl = NULL;
            inst->key[0] = '\0';
            MW_UNLOCK();
        }
        return;
    }
    if (!inst) {
        *aviFAIL = -1;
        mw_msg(msg, "mpc-wt controller: called with status %d for '%s' before its first call "
               "(status 0)", status, key);
        copy_msg(avcMSG, msg_len, msg);
        return;
    }
    read_meas(avrSWAP, &m);
    /* the time in double precision: the swap array's float32 time has 61 us steps at 600 s,
     * the interval is the design's (checked at the first call) */
    m.t = inst->t0 + (double)inst->calls * inst->ctrl->dt;
    inst->calls++;
    cmd.nlog = 0;
    rc = inst->ctrl->step(inst->ctrl, &m, &cmd, msg);
    if (rc < 0) {
        *aviFAIL = -1;
        copy_msg(avcMSG, msg_len, msg);
        return;
    }
    if (rc > 0) {                                   /* a warning: the command still applies */
        *aviFAIL = 1;
        copy_msg(avcMSG, msg_len, msg);
    }
    write_cmd(avrSWAP, &cmd);
}
