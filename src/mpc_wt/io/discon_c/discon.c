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
    m->lidar_type = m->lidar_beams = m->lidar_gates = 0;
    m->los[0] = m->los[1] = m->los[2] = 0.0;
    if (s[128] >= 2007.0f) {        /* record 129: the array's length; the lidar block fits */
        m->lidar_type = (int)s[2000];
        m->lidar_beams = (int)s[2001];
        m->lidar_gates = (int)s[2002];
        m->los[0] = s[2004];
        m->los[1] = s[2005];
        m->los[2] = s[2006];
    }
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
