/*
 * bdot_detumble.c - a B-dot detumble in C on a lockstep flexdyn server: the magnetometer in, the
 * magnetorquer rods out, nothing else (no gyro, no truth).
 *
 * The law (Stickler & Alfriend, "Elementary magnetic attitude control system", J. Spacecraft
 * 13(5), 1976): command the dipole m = -k dB/dt, with dB/dt the rate of change of the field
 * measured in the body. For a field fixed in N, dB_B/dt = -omega x B_B, so the torque
 * m x B = k [B (omega . B) - omega |B|^2] takes rotational energy out at the rate
 * -k |omega x B|^2 <= 0. dB/dt is the difference of the magnetometer samples one second apart
 * (ten 10 Hz samples): the 50 nT noise of scenarios/acs_full.toml's magnetometer over 0.1 s would
 * be 7e-7 T/s, as large as the signal at 1 deg/s; over 1 s it is ten times smaller. Each rod is
 * clipped to its limit on its own, which keeps the sign of every component and so the law
 * dissipative. The magnetometer's frame S is B (dcm_sb = identity in acs_full.toml), and the
 * rods are the StateMsg's magnetorquer effectors (kind FD_EFFECTOR_MAGNETORQUER) in order, along
 * +x, +y, +z of B, each up to 400 A m^2 (acs_full.toml's [[magnetorquers]]).
 *
 * The rate it reports is the truth's (StateMsg omega_bn_b_rad_s), for judging the run only; the
 * control law never reads it. A tick without a magnetometer sample is an error (exit 4): the law
 * cannot run without it.
 *
 * Usage: bdot_detumble <endpoint> <gain_am2_s_per_t> <state_out|->
 *   gain   k in A m^2 per T/s (4e8 detumbles acs_full.toml; 0 commands nothing, the control)
 *   state_out  every state, re-encoded, behind its u32 LE length ("-": none)
 * Runs until the server ends the run. Prints "below 1 deg/s at t = <s> s" the first time the
 * true rate falls below 1 deg/s, and at the end "final |omega| = <deg/s> deg/s after <n> ticks".
 * Exit codes: 0 done, 2 usage, 3 no tick within 10 s, 4 any other error.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "flexdyn_client.h"

#define SENDER_ID 1u
#define MAX_DIPOLE_AM2 400.0
#define BASELINE_TICKS 10u /* dB/dt over 10 samples of the 10 Hz magnetometer: 1 s */
#define THRESHOLD_DEG_S 1.0

static fd_effector_state effectors[FD_MAX_EFFECTORS];

static int record(FILE *out, const fd_state_msg *st) {
    static uint8_t buf[FD_MAX_MESSAGE_BYTES];
    uint8_t len_le[4];
    size_t n = fd_encode_state(st, buf, sizeof buf);
    if (n == 0) return -1;
    len_le[0] = (uint8_t)n;
    len_le[1] = (uint8_t)(n >> 8);
    len_le[2] = (uint8_t)(n >> 16);
    len_le[3] = (uint8_t)(n >> 24);
    if (fwrite(len_le, 1, 4, out) != 4 || fwrite(buf, 1, n, out) != n) return -1;
    return 0;
}

static double clip(double x, double limit) { return x > limit ? limit : (x < -limit ? -limit : x); }

int main(int argc, char **argv) {
    const char *connect[1];
    flexdyn_options opts;
    flexdyn_client *c;
    fd_state_msg st;
    fd_magnetometer_msg mag;
    fd_effector_input rods[3];
    double history[BASELINE_TICKS + 1][3]; /* the last samples, oldest first once full */
    double history_t[BASELINE_TICKS + 1];
    size_t n_history = 0, n_rods, i, a;
    const double zero[3] = {0.0, 0.0, 0.0};
    double gain, rate_deg_s = 0.0;
    unsigned long ticks = 0;
    int rc, below = 0;
    FILE *out = NULL;
    if (argc != 4) {
        fprintf(stderr, "usage: bdot_detumble <endpoint> <gain> <state_out|->\n");
        return 2;
    }
    gain = strtod(argv[2], NULL);
    if (strcmp(argv[3], "-") != 0 && (out = fopen(argv[3], "wb")) == NULL) {
        perror(argv[3]);
        return 4;
    }
    c = flexdyn_client_new();
    if (c == NULL) return 4;
    connect[0] = argv[1];
    memset(&opts, 0, sizeof opts);
    opts.connect = connect;
    opts.n_connect = 1;
    if (flexdyn_open(c, &opts) != FLEXDYN_OK || flexdyn_lockstep_join(c, SENDER_ID, 10000) != FLEXDYN_OK) {
        fprintf(stderr, "join: %s\n", flexdyn_last_error(c));
        return 4;
    }
    if (flexdyn_lockstep_magnetometer_count(c) < 1) {
        fprintf(stderr, "the run has no magnetometer\n");
        return 4;
    }
    memset(&st, 0, sizeof st);
    st.effectors = effectors;
    st.effectors_capacity = FD_MAX_EFFECTORS;
    while ((rc = flexdyn_lockstep_wait(c, &st, 10000)) == FLEXDYN_OK) {
        double b_dot[3] = {0.0, 0.0, 0.0}, t_s = (double)st.header.sim_time_ns * 1e-9;
        ++ticks;
        if (out != NULL && record(out, &st) != 0) {
            fprintf(stderr, "cannot write %s\n", argv[3]);
            return 4;
        }
        rate_deg_s = sqrt(st.omega_bn_b_rad_s[0] * st.omega_bn_b_rad_s[0] +
                          st.omega_bn_b_rad_s[1] * st.omega_bn_b_rad_s[1] +
                          st.omega_bn_b_rad_s[2] * st.omega_bn_b_rad_s[2]) *
                     180.0 / 3.14159265358979323846;
        if (!below && rate_deg_s < THRESHOLD_DEG_S) {
            below = 1;
            printf("below %.1f deg/s at t = %.1f s\n", THRESHOLD_DEG_S, t_s);
            fflush(stdout);
        }
        rc = flexdyn_lockstep_magnetometer(c, 0, &mag);
        if (rc != FLEXDYN_OK) {
            fprintf(stderr, "tick %llu: no magnetometer sample: %s\n",
                    (unsigned long long)st.header.tick, flexdyn_last_error(c));
            return 4;
        }
        if (n_history == BASELINE_TICKS + 1) {
            memmove(history, history[1], sizeof history[0] * BASELINE_TICKS);
            memmove(history_t, history_t + 1, sizeof history_t[0] * BASELINE_TICKS);
            --n_history;
        }
        for (a = 0; a < 3; ++a) history[n_history][a] = mag.b_s_t[a];
        history_t[n_history] = (double)mag.header.sim_time_ns * 1e-9;
        ++n_history;
        if (n_history > 1) {
            double dt = history_t[n_history - 1] - history_t[0];
            for (a = 0; a < 3; ++a) b_dot[a] = (history[n_history - 1][a] - history[0][a]) / dt;
        }
        n_rods = 0;
        for (i = 0; i < st.n_effectors && n_rods < 3; ++i) {
            if (st.effectors[i].kind != FD_EFFECTOR_MAGNETORQUER) continue;
            memset(&rods[n_rods], 0, sizeof rods[n_rods]);
            rods[n_rods].effector_index = (uint32_t)i;
            rods[n_rods].n_values = 1;
            rods[n_rods].values[0] = clip(-gain * b_dot[n_rods], MAX_DIPOLE_AM2);
            ++n_rods;
        }
        if (n_rods != 3) {
            fprintf(stderr, "the run has %lu magnetorquers, the law needs 3\n", (unsigned long)n_rods);
            return 4;
        }
        if (flexdyn_lockstep_answer_actuators(c, zero, zero, rods, 3) != FLEXDYN_OK) {
            fprintf(stderr, "answer: %s\n", flexdyn_last_error(c));
            return 4;
        }
    }
    if (out != NULL) fclose(out);
    if (rc != FLEXDYN_ENDED) {
        fprintf(stderr, "wait: %s\n", flexdyn_last_error(c));
        return rc == FLEXDYN_ERR_TIMEOUT ? 3 : 4;
    }
    printf("final |omega| = %.4f deg/s after %lu ticks\n", rate_deg_s, ticks);
    flexdyn_client_free(c);
    return 0;
}
