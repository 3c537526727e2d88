/*
 * pd_lockstep.c - C flight code on a lockstep flexdyn server, through libflexdyn_client.
 *
 * Each tick: the state of tick k and every sensor sample due at k (one complete tick from
 * flexdyn_lockstep_wait), the MRP PD law L = -K sigma_BN - P omega (omega from the first IMU's
 * gyro when the run has one, else the true rate), and one answer: an Actuators command with the
 * PD torque and a small damping torque -C Omega on every reaction wheel, or a Wrench command
 * when there are no wheels. The IMU frame P is taken to be B (dcm_pb = identity, as in
 * scenarios/wheels_star_tracker.toml). Star-tracker samples are checked to be there on the ticks
 * they are due.
 *
 * The loop runs until the server ends the run: flexdyn_lockstep_wait hands out every tick
 * received, then returns FLEXDYN_ENDED, and flexdyn_run_ended says how the run ended (the
 * server's last StatusMsg). No timeout is involved in stopping.
 *
 * Usage: pd_lockstep <endpoint> <last_tick|-> <state_out|-> [timeout_ms]
 *   endpoint   the server's Zenoh endpoint, e.g. tcp/127.0.0.1:7447
 *   last_tick  "-": answer every tick until the run ends; a number: also leave (close, exit 0)
 *              after answering that tick if the run goes on
 *   state_out  a file that receives every state, re-encoded with fd_encode_state, each behind
 *              its u32 little-endian length ("-": none)
 *   timeout_ms how long to wait for a tick before giving up on a server that vanished without
 *              ending the run (default 5000)
 * Prints "tick <k>" every 500 ticks, and at the end "run ended: <finished|stopped|failed> at
 * tick <n>, <m> ticks answered" (or "left after tick <n>, <m> ticks answered"). Exit codes:
 * 0 done (the run finished or was stopped, or last_tick was reached), 1 the server says the run
 * failed, 2 usage, 3 no tick within the timeout (the server is gone), 4 any other error.
 *
 * Build (README, "Attaching flight code"):
 *   cc -std=c99 -Wall -Wextra -I proto/c/include -I clients/c/include \
 *      clients/c/examples/pd_lockstep.c target/release/libflexdyn_client.a \
 *      -ldl -lgcc_s -lutil -lrt -lpthread -lm -lc -o pd_lockstep
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "flexdyn_client.h"

#define SENDER_ID 1u
#define K_NM 10.0        /* attitude gain [N m per unit MRP] */
#define P_NMS 150.0      /* rate gain [N m s/rad] */
#define C_WHEEL_NMS 1e-4 /* wheel-speed damping [N m s/rad] */

static fd_effector_state effectors[FD_MAX_EFFECTORS];
static fd_effector_input inputs[FD_MAX_EFFECTORS];

/* Appends the state, re-encoded, behind its u32 LE length. */
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

/* The answer to one complete tick. */
static int answer(flexdyn_client *c, const fd_state_msg *st) {
    double omega[3], torque[3], force[3] = {0.0, 0.0, 0.0};
    size_t i, n_inputs = 0;
    fd_imu_msg imu;
    memcpy(omega, st->omega_bn_b_rad_s, sizeof omega);
    if (flexdyn_lockstep_imu_count(c) > 0) {
        if (flexdyn_lockstep_imu(c, 0, &imu) != FLEXDYN_OK) return FLEXDYN_ERR_ABSENT;
        memcpy(omega, imu.omega_p_rad_s, sizeof omega);
    }
    for (i = 0; i < flexdyn_lockstep_star_tracker_count(c); ++i) {
        fd_star_tracker_msg s;
        int rc = flexdyn_lockstep_star_tracker(c, i, &s);
        if (rc == FLEXDYN_OK && s.header.tick != st->header.tick) return FLEXDYN_ERR_ABSENT;
        if (rc != FLEXDYN_OK && rc != FLEXDYN_ERR_ABSENT) return rc;
    }
    for (i = 0; i < 3; ++i) torque[i] = -K_NM * st->sigma_bn[i] - P_NMS * omega[i];
    for (i = 0; i < st->n_effectors; ++i) {
        const fd_effector_state *e = &st->effectors[i];
        if (e->kind != FD_EFFECTOR_REACTION_WHEEL || e->n_states < 1) continue;
        memset(&inputs[n_inputs], 0, sizeof inputs[n_inputs]);
        inputs[n_inputs].effector_index = (uint32_t)i;
        inputs[n_inputs].n_values = 1;
        inputs[n_inputs].values[0] = -C_WHEEL_NMS * e->states[0];
        ++n_inputs;
    }
    if (n_inputs > 0)
        return flexdyn_lockstep_answer_actuators(c, torque, force, inputs, n_inputs);
    return flexdyn_lockstep_answer_wrench(c, torque, force);
}

static int fail(flexdyn_client *c, const char *what, int rc) {
    fprintf(stderr, "pd_lockstep: %s: %s (code %d)\n", what, flexdyn_last_error(c), rc);
    flexdyn_client_free(c);
    return rc == FLEXDYN_ERR_TIMEOUT ? 3 : 4;
}

/* The word of an ended run's state. */
static const char *ended_word(int32_t run_state) {
    switch (run_state) {
    case (int32_t)FD_RUN_STATE_FINISHED: return "finished";
    case (int32_t)FD_RUN_STATE_STOPPED: return "stopped";
    default: return "failed";
    }
}

int main(int argc, char **argv) {
    flexdyn_options opts;
    flexdyn_client *c;
    fd_state_msg st;
    FILE *out = NULL;
    unsigned long long last = 0, k;
    unsigned long timeout_ms = 5000;
    int rc, bounded, ended = 0;
    int32_t run_state = (int32_t)FD_RUN_STATE_RUNNING;
    uint64_t end_tick = 0;
    if (argc < 4 || argc > 5) {
        fprintf(stderr, "usage: %s <endpoint> <last_tick|-> <state_out|-> [timeout_ms]\n",
                argv[0]);
        return 2;
    }
    bounded = strcmp(argv[2], "-") != 0;
    if (bounded) last = strtoull(argv[2], NULL, 10);
    if (argc == 5) timeout_ms = strtoul(argv[4], NULL, 10);

    c = flexdyn_client_new();
    if (c == NULL) return 4;
    memset(&opts, 0, sizeof opts);
    opts.connect = (const char *const *)&argv[1];
    opts.n_connect = 1;
    if ((rc = flexdyn_open(c, &opts)) != FLEXDYN_OK) return fail(c, "open", rc);
    /* The server's configuration, the telemetry subscription, then the liveliness token. */
    if ((rc = flexdyn_lockstep_join(c, SENDER_ID, 30000)) != FLEXDYN_OK)
        return fail(c, "join", rc);
    if (strcmp(argv[3], "-") != 0 && (out = fopen(argv[3], "wb")) == NULL) {
        fprintf(stderr, "pd_lockstep: cannot write %s\n", argv[3]);
        flexdyn_client_free(c);
        return 4;
    }

    memset(&st, 0, sizeof st);
    st.effectors = effectors;
    st.effectors_capacity = FD_MAX_EFFECTORS;
    for (k = 0; !bounded || k <= last; ++k) {
        rc = flexdyn_lockstep_wait(c, &st, (uint32_t)timeout_ms);
        if (rc == FLEXDYN_ENDED) {
            /* Every tick the server published was handed out: the run is over. */
            if (flexdyn_run_ended(c, &run_state, &end_tick) != 1) {
                fprintf(stderr, "pd_lockstep: FLEXDYN_ENDED without an end of run\n");
                if (out != NULL) fclose(out);
                flexdyn_client_free(c);
                return 4;
            }
            ended = 1;
            break;
        }
        if (rc != FLEXDYN_OK) {
            if (out != NULL) fclose(out);
            return fail(c, "wait", rc);
        }
        if (st.header.tick != k) {
            fprintf(stderr, "pd_lockstep: tick %llu where %llu was due\n",
                    (unsigned long long)st.header.tick, k);
            if (out != NULL) fclose(out);
            flexdyn_client_free(c);
            return 4;
        }
        if (out != NULL && record(out, &st) != 0) {
            fprintf(stderr, "pd_lockstep: cannot record tick %llu\n", k);
            fclose(out);
            flexdyn_client_free(c);
            return 4;
        }
        if ((rc = answer(c, &st)) != FLEXDYN_OK) {
            if (out != NULL) fclose(out);
            return fail(c, "answer", rc);
        }
        if (k % 500 == 0) {
            printf("tick %llu\n", k);
            fflush(stdout);
        }
    }
    if (out != NULL && fclose(out) != 0) {
        fprintf(stderr, "pd_lockstep: cannot write %s\n", argv[3]);
        flexdyn_client_free(c);
        return 4;
    }
    rc = flexdyn_close(c);
    if (rc != FLEXDYN_OK) return fail(c, "close", rc);
    flexdyn_client_free(c);
    if (ended) {
        printf("run ended: %s at tick %llu, %llu ticks answered\n", ended_word(run_state),
               (unsigned long long)end_tick, k);
        return run_state == (int32_t)FD_RUN_STATE_FAILED ? 1 : 0;
    }
    printf("left after tick %llu, %llu ticks answered\n", last, last + 1);
    return 0;
}
