/*
 * every_message.c - the calls of flexdyn_client_messages.h (generated from the wire table) against
 * a real lockstep server on scenarios/acs_full.toml, as participant 1:
 *   - every sensor kind of the run, from the held tick (IMU, star tracker, magnetometer, coarse and
 *     fine sun sensors), with the names and counts of the served configuration;
 *   - the environment message and fault events by subscription;
 *   - a live fault injected with flexdyn_inject_fault (the magnetometer stuck at 25 uT from tick 5)
 *     and seen twice: as its FaultEventMsg, and in the magnetometer's samples;
 *   - a fault the server must refuse (an unknown target), seen in the last StatusMsg;
 *   - the byte-level calls' refusals (a kind the server publishes, a kind out of range).
 *
 * Usage: every_message <endpoint>; runs until the server ends the run, prints one summary line
 * and exits 0 when every check held (each failure is printed on stderr).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "flexdyn_client.h"

static int bad = 0;

static void check(int ok, const char *what, flexdyn_client *c) {
    if (!ok) {
        fprintf(stderr, "FAILED: %s (last error: %s)\n", what, flexdyn_last_error(c));
        bad = 1;
    }
}

static double norm3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

#define STUCK_T 2.5e-5
#define FAULT_TICK 5u

int main(int argc, char **argv) {
    static fd_effector_state effectors[FD_MAX_EFFECTORS];
    const char *connect[1];
    flexdyn_options opts;
    flexdyn_client *c;
    fd_state_msg st;
    fd_environment_msg env;
    fd_fault_event_msg ev;
    fd_status_msg status;
    size_t n_mag, n_css, n_fss, n_gps, i;
    unsigned long mag = 0, css = 0, fss = 0, imu = 0, star = 0, envs = 0, events = 0, stuck = 0;
    unsigned long ticks = 0;
    int rc, saw_event = 0, have_status = 0;
    const double stuck_params[2] = {STUCK_T, 0.0};
    const uint8_t *bytes = NULL;
    size_t len = 0;
    uint8_t junk[4] = {0, 0, 0, 0};
    if (argc != 2) return 2;
    c = flexdyn_client_new();
    if (c == NULL) return 2;
    connect[0] = argv[1];
    memset(&opts, 0, sizeof opts);
    opts.connect = connect;
    opts.n_connect = 1;
    check(flexdyn_open(c, &opts) == FLEXDYN_OK, "open", c);
    check(flexdyn_subscribe_environment(c, 256) == FLEXDYN_OK, "subscribe_environment", c);
    check(flexdyn_subscribe_fault_event(c, 16) == FLEXDYN_OK, "subscribe_fault_event", c);
    check(flexdyn_subscribe_status(c, 64) == FLEXDYN_OK, "subscribe_status", c);
    check(flexdyn_lockstep_join(c, 1, 20000) == FLEXDYN_OK, "lockstep_join", c);
    if (bad) return 1;

    /* The served configuration's sensors. */
    n_mag = flexdyn_lockstep_magnetometer_count(c);
    n_css = flexdyn_lockstep_css_count(c);
    n_fss = flexdyn_lockstep_fss_count(c);
    n_gps = flexdyn_lockstep_gps_count(c);
    check(n_mag == 1 && strcmp(flexdyn_lockstep_magnetometer_name(c, 0), "mag1") == 0,
          "one magnetometer, mag1", c);
    check(n_css == 1 && strcmp(flexdyn_lockstep_css_name(c, 0), "css") == 0, "one css, css", c);
    check(n_fss == 1 && strcmp(flexdyn_lockstep_fss_name(c, 0), "fss") == 0, "one fss, fss", c);
    check(n_gps == 0, "no GPS receiver", c);
    check(flexdyn_lockstep_magnetometer_name(c, 1) == NULL, "name out of range is NULL", c);
    check(flexdyn_lockstep_sensor_count(c, FLEXDYN_KIND_STATUS) == 0, "status is no sensor", c);
    check(flexdyn_lockstep_sensor_count(c, 99) == 0, "kind 99 has no sensors", c);

    /* The byte-level calls refuse what they must. */
    check(flexdyn_publish_bytes(c, FLEXDYN_KIND_STATE, junk, sizeof junk) == FLEXDYN_ERR_USAGE,
          "publishing a server message is refused", c);
    check(flexdyn_publish_bytes(c, FLEXDYN_KIND_FAULT_COMMAND, junk, sizeof junk) ==
              FLEXDYN_ERR_ARGUMENT,
          "publishing undecodable bytes is refused", c);
    check(flexdyn_subscribe_kind(c, FLEXDYN_KIND_COUNT, NULL, 1) == FLEXDYN_ERR_ARGUMENT,
          "kind FLEXDYN_KIND_COUNT is out of range", c);
    check(flexdyn_poll_bytes(c, FLEXDYN_KIND_GPS, &bytes, &len, NULL, 0) == FLEXDYN_ERR_USAGE,
          "polling an unsubscribed kind is a usage error", c);
    check(flexdyn_subscribe_magnetometer(c, "no such name!", 1) == FLEXDYN_ERR_ARGUMENT,
          "a name that is no key chunk is refused", c);
    check(flexdyn_poll_environment(c, NULL) == FLEXDYN_ERR_ARGUMENT, "a NULL out is refused", c);

    memset(&st, 0, sizeof st);
    st.effectors = effectors;
    st.effectors_capacity = FD_MAX_EFFECTORS;
    for (;;) {
        fd_imu_msg mi;
        fd_star_tracker_msg ms;
        fd_magnetometer_msg mm;
        fd_css_msg mc;
        fd_fss_msg mf;
        memset(&mm, 0, sizeof mm);
        memset(&mc, 0, sizeof mc);
        memset(&mf, 0, sizeof mf);
        rc = flexdyn_lockstep_wait(c, &st, 20000);
        if (rc == FLEXDYN_ENDED) break;
        if (rc != FLEXDYN_OK) {
            check(0, "lockstep_wait", c);
            break;
        }
        ++ticks;
        for (i = 0; i < flexdyn_lockstep_imu_count(c); ++i)
            if (flexdyn_lockstep_imu(c, i, &mi) == FLEXDYN_OK) ++imu;
        for (i = 0; i < flexdyn_lockstep_star_tracker_count(c); ++i)
            if (flexdyn_lockstep_star_tracker(c, i, &ms) == FLEXDYN_OK) ++star;
        rc = flexdyn_lockstep_magnetometer(c, 0, &mm);
        check(rc == FLEXDYN_OK, "a magnetometer sample every tick (10 Hz of 10 Hz)", c);
        if (rc == FLEXDYN_OK) {
            ++mag;
            check(mm.header.tick == st.header.tick, "the sample is the held tick's", c);
            if (mm.header.tick >= FAULT_TICK) {
                /* stuck_value: every axis reads the value (quantised to the 10 nT lsb). */
                check(fabs(mm.b_s_t[0] - STUCK_T) < 1e-8 && fabs(mm.b_s_t[1] - STUCK_T) < 1e-8 &&
                          fabs(mm.b_s_t[2] - STUCK_T) < 1e-8,
                      "the magnetometer is stuck from the fault's tick on", c);
                ++stuck;
            } else {
                /* Low Earth orbit: 20..60 uT, and not the stuck value. */
                check(norm3(mm.b_s_t) > 1.5e-5 && norm3(mm.b_s_t) < 6.5e-5,
                      "a LEO field magnitude before the fault", c);
            }
        }
        rc = flexdyn_lockstep_css(c, 0, &mc);
        check(rc == FLEXDYN_OK && mc.detector_count == 6, "a six-detector css sample", c);
        if (rc == FLEXDYN_OK) ++css;
        rc = flexdyn_lockstep_fss(c, 0, &mf);
        check(rc == FLEXDYN_OK && (mf.flags & ~0x07u) == 0, "an fss sample", c);
        if (rc == FLEXDYN_OK) ++fss;
        check(flexdyn_lockstep_magnetometer(c, 1, &mm) == FLEXDYN_ERR_ARGUMENT,
              "index 1 of one magnetometer is refused", c);

        if (st.header.tick == FAULT_TICK - 1) {
            /* Put before the answer to tick 4, so the fault is in force at boundary 5. */
            check(flexdyn_inject_fault(c, &st.header, 0, "magnetometers.mag1", 1u, stuck_params, 0u,
                                       FAULT_TICK, 0u, 0u) == FLEXDYN_OK,
                  "inject_fault", c);
            check(flexdyn_inject_fault(c, &st.header, 1, "magnetometers.nope", 1u, stuck_params,
                                       0u, FAULT_TICK, 0u, 0u) == FLEXDYN_OK,
                  "inject_fault (a target the server refuses)", c);
        }
        while (flexdyn_poll_environment(c, &env) == FLEXDYN_OK) {
            ++envs;
            check((env.flags & 0x02u) != 0 && norm3(env.b_n_t) > 1.5e-5,
                  "the environment has a magnetic field", c);
        }
        while (flexdyn_poll_fault_event(c, &ev) == FLEXDYN_OK) {
            ++events;
            check(ev.source == FD_FAULT_SOURCE_LIVE && ev.active == 1 && ev.mode == 1 &&
                      ev.header.tick == FAULT_TICK &&
                      strcmp((const char *)ev.target, "magnetometers.mag1") == 0 &&
                      ev.params[0] == STUCK_T,
                  "the fault event names the injected fault", c);
            saw_event = 1;
        }
        check(flexdyn_lockstep_answer_no_command(c) == FLEXDYN_OK, "answer", c);
    }
    /* Each tick's environment message follows its state: the last may come after the end. */
    while (flexdyn_poll_environment(c, &env) == FLEXDYN_OK) ++envs;
    while (flexdyn_poll_status(c, &status) == FLEXDYN_OK) have_status = 1;
    check(have_status && status.rejected_fault_refused == 1,
          "the last status counts the refused fault", c);
    check(saw_event && events == 1, "exactly one fault event", c);
    check(ticks > 20 && imu == ticks && mag == ticks && css == ticks && fss == ticks,
          "every tick carried every sensor", c);
    check(envs == ticks, "an environment message each tick (10 Hz of 10 Hz)", c);
    printf("ticks %lu imu %lu star %lu mag %lu (stuck %lu) css %lu fss %lu env %lu events %lu\n",
           ticks, imu, star, mag, stuck, css, fss, envs, events);
    flexdyn_client_free(c);
    return bad;
}
