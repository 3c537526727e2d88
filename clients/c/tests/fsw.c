/*
 * fsw.c - the flight code's own telemetry from C (flexdyn_fsw_*, protocol 10), against a real
 * lockstep server as participant 1. The server's configuration (clients/c/tests/c_client.rs,
 * fsw_telemetry_from_c_is_recorded_bit_for_bit, writes it) declares
 *
 *   [[fsw_streams]]
 *   name = "acs"
 *   modes = ["detumble", "point"]
 *   events = [{ name = "gyro_fault", severity = "error" }]
 *   values = [{ name = "h_b_nms", type = "f64", len = 3 }, { name = "flags", type = "i64" },
 *             { name = "ok", type = "bool" }]
 *
 * Before its answer to each tick k below <last tick> it publishes one sample stamped with the
 * state of tick k, its values derived from k (the test reads them back from the recording):
 * mode "detumble" before tick 10 and "point" from it, the estimate {0.6, 0.8, 0, 0} on every
 * tick, the target {0, 0, 0.6, 0.8} from tick 10, the event "gyro_fault" at tick 5, a variance
 * {1e-6, 2e-6, 3e-6} at tick 3, h_b_nms = {k/2, -k, 0.25}, flags = -k, ok = k % 2.
 * On the way it checks the library's own refusals: each returns its code, names the stream and
 * the field, and sends nothing (the server's last StatusMsg must count no refused sample).
 *
 * Usage: fsw <endpoint> <last tick>; prints one summary line and exits 0 when every check held
 * (each failure is printed on stderr).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "flexdyn_client.h"

static int bad = 0;
static unsigned long refusals = 0;

static void check(int ok, const char *what, const char *last_error) {
    if (!ok) {
        fprintf(stderr, "FAILED: %s (last error: %s)\n", what, last_error);
        bad = 1;
    }
}

/* A call that must be refused with `code` and a message holding `needle`. */
static void refused(flexdyn_fsw_stream *acs, int rc, int code, const char *needle,
                    const char *what) {
    const char *m = flexdyn_fsw_last_error(acs);
    check(rc == code, what, m);
    check(strstr(m, "stream `acs`") != NULL && strstr(m, needle) != NULL,
          "the refusal names the stream and the field", m);
    ++refusals;
}

static const double Q_EST[4] = {0.6, 0.8, 0.0, 0.0};
static const double Q_TARGET[4] = {0.0, 0.0, 0.6, 0.8};
static const double VARIANCE[3] = {1e-6, 2e-6, 3e-6};

/* The sample of tick k; at tick 3, the refusals on the way to it. */
static void sample(flexdyn_fsw_stream *acs, const fd_header *stamp) {
    uint64_t k = stamp->tick;
    double h_b_nms[3];
    int64_t flags = -(int64_t)k;
    int ok = (int)(k % 2);
    h_b_nms[0] = (double)k * 0.5;
    h_b_nms[1] = -(double)k;
    h_b_nms[2] = 0.25;
    if (k == 3) {
        double nan3[3];
        double two[2] = {1.0, 2.0};
        fd_header other = *stamp;
        check(flexdyn_fsw_begin(acs, stamp) == FLEXDYN_OK, "begin", flexdyn_fsw_last_error(acs));
        nan3[0] = 0.0;
        nan3[1] = NAN;
        nan3[2] = 0.0;
        refused(acs, flexdyn_fsw_set_mode(acs, "safe"), FLEXDYN_ERR_ARGUMENT, "\"safe\"",
                "an undeclared mode");
        refused(acs, flexdyn_fsw_add_event(acs, "sun_lost"), FLEXDYN_ERR_ARGUMENT,
                "\"sun_lost\"", "an undeclared event");
        refused(acs, flexdyn_fsw_set_f64(acs, "h_b_nms", two, 2), FLEXDYN_ERR_ARGUMENT,
                "`h_b_nms` has 3 elements, got 2", "a wrong length");
        refused(acs, flexdyn_fsw_set_f64(acs, "flags", two, 1), FLEXDYN_ERR_ARGUMENT,
                "`flags` is i64, not f64", "a wrong type");
        refused(acs, flexdyn_fsw_set_f64(acs, "h_b_nms", nan3, 3), FLEXDYN_ERR_ARGUMENT,
                "`h_b_nms[1]` = NaN", "a non-finite f64");
        refused(acs, flexdyn_fsw_set_bool(acs, "sun_valid", &ok, 1), FLEXDYN_ERR_ARGUMENT,
                "\"sun_valid\"", "an undeclared value");
        other.spacecraft_id += 1;
        refused(acs, flexdyn_fsw_begin(acs, &other), FLEXDYN_ERR_ARGUMENT, "spacecraft_id",
                "another spacecraft's stamp");
        /* The refusals changed nothing: the sample begun is still the one of tick 3. */
        check(flexdyn_fsw_set_mode(acs, "detumble") == FLEXDYN_OK, "set_mode",
              flexdyn_fsw_last_error(acs));
        check(flexdyn_fsw_set_variance(acs, VARIANCE) == FLEXDYN_OK, "set_variance",
              flexdyn_fsw_last_error(acs));
        check(flexdyn_fsw_set_f64(acs, "h_b_nms", h_b_nms, 3) == FLEXDYN_OK, "set_f64",
              flexdyn_fsw_last_error(acs));
        check(flexdyn_fsw_set_i64(acs, "flags", &flags, 1) == FLEXDYN_OK, "set_i64",
              flexdyn_fsw_last_error(acs));
        /* A value left out: nothing is sent, and the sample stays begun. */
        refused(acs, flexdyn_fsw_publish(acs), FLEXDYN_ERR_USAGE, "lacks value `ok`",
                "a sample with a value not set");
        check(flexdyn_fsw_set_bool(acs, "ok", &ok, 1) == FLEXDYN_OK, "set_bool",
              flexdyn_fsw_last_error(acs));
        refused(acs, flexdyn_fsw_publish(acs), FLEXDYN_ERR_USAGE, "variance without an estimate",
                "a variance without an estimate");
        check(flexdyn_fsw_set_estimate(acs, Q_EST) == FLEXDYN_OK, "set_estimate",
              flexdyn_fsw_last_error(acs));
        check(flexdyn_fsw_publish(acs) == FLEXDYN_OK, "publish", flexdyn_fsw_last_error(acs));
    } else {
        /* One sample per tick, by the names the configuration declares: the library counts. */
        int rc = flexdyn_fsw_begin(acs, stamp); /* the state this tick answers */
        if (rc == FLEXDYN_OK) rc = flexdyn_fsw_set_mode(acs, k < 10 ? "detumble" : "point");
        if (rc == FLEXDYN_OK && k == 5) rc = flexdyn_fsw_add_event(acs, "gyro_fault");
        if (rc == FLEXDYN_OK) rc = flexdyn_fsw_set_estimate(acs, Q_EST);
        if (rc == FLEXDYN_OK && k >= 10) rc = flexdyn_fsw_set_target(acs, Q_TARGET);
        if (rc == FLEXDYN_OK) rc = flexdyn_fsw_set_f64(acs, "h_b_nms", h_b_nms, 3);
        if (rc == FLEXDYN_OK) rc = flexdyn_fsw_set_i64(acs, "flags", &flags, 1);
        if (rc == FLEXDYN_OK) rc = flexdyn_fsw_set_bool(acs, "ok", &ok, 1);
        if (rc == FLEXDYN_OK) rc = flexdyn_fsw_publish(acs);
        check(rc == FLEXDYN_OK, "the sample of a tick", flexdyn_fsw_last_error(acs));
    }
    if (k == 4) {
        /* At most one sample per tick per stream. */
        refused(acs, flexdyn_fsw_begin(acs, stamp), FLEXDYN_ERR_USAGE,
                "at most one sample per tick", "a second sample for a tick");
        refused(acs, flexdyn_fsw_set_mode(acs, "point"), FLEXDYN_ERR_USAGE, "no sample begun",
                "a setter after the sample was published");
    }
}

int main(int argc, char **argv) {
    static fd_effector_state effectors[FD_MAX_EFFECTORS];
    const char *connect[1];
    flexdyn_options opts;
    flexdyn_client *c;
    flexdyn_fsw_stream *acs = NULL;
    flexdyn_fsw_stream *none = NULL;
    fd_state_msg st;
    fd_status_msg status;
    unsigned long last_tick, published = 0;
    int rc, have_status = 0;
    if (argc != 3) return 2;
    last_tick = strtoul(argv[2], NULL, 10);
    c = flexdyn_client_new();
    if (c == NULL) return 2;
    connect[0] = argv[1];
    memset(&opts, 0, sizeof opts);
    opts.connect = connect;
    opts.n_connect = 1;
    check(flexdyn_open(c, &opts) == FLEXDYN_OK, "open", flexdyn_last_error(c));
    check(flexdyn_subscribe_status(c, 64) == FLEXDYN_OK, "subscribe_status",
          flexdyn_last_error(c));

    /* A stream the configuration does not declare: the message names it and the declared ones. */
    rc = flexdyn_fsw_declare(c, "gnc", &none, 20000);
    check(rc == FLEXDYN_ERR_ARGUMENT && none == NULL, "an undeclared stream is refused",
          flexdyn_last_error(c));
    check(strstr(flexdyn_last_error(c), "\"gnc\"") != NULL &&
              strstr(flexdyn_last_error(c), "(declared: \"acs\")") != NULL,
          "the refusal names the stream and the declared ones", flexdyn_last_error(c));
    check(flexdyn_fsw_set_mode(NULL, "point") == FLEXDYN_ERR_ARGUMENT, "a NULL stream",
          flexdyn_fsw_last_error(NULL));
    check(flexdyn_publish_bytes(c, FLEXDYN_KIND_FSW, (const uint8_t *)"x", 1) ==
              FLEXDYN_ERR_USAGE,
          "fsw samples are not published by kind", flexdyn_last_error(c));
    refusals += 3;

    /* The stream of the served configuration's [[fsw_streams]], by its name. */
    if (flexdyn_fsw_declare(c, "acs", &acs, 20000) != FLEXDYN_OK) {
        fprintf(stderr, "FAILED: declare (last error: %s)\n", flexdyn_last_error(c));
        return 1;
    }
    check(flexdyn_lockstep_join(c, 1, 20000) == FLEXDYN_OK, "lockstep_join",
          flexdyn_last_error(c));
    if (bad) return 1;
    refused(acs, flexdyn_fsw_publish(acs), FLEXDYN_ERR_USAGE, "no sample begun",
            "publishing before a begin");

    memset(&st, 0, sizeof st);
    st.effectors = effectors;
    st.effectors_capacity = FD_MAX_EFFECTORS;
    for (;;) {
        rc = flexdyn_lockstep_wait(c, &st, 20000);
        if (rc == FLEXDYN_ENDED) break;
        if (rc != FLEXDYN_OK) {
            check(0, "lockstep_wait", flexdyn_last_error(c));
            break;
        }
        /* The last tick needs no answer: the run is over once it is out. */
        if (st.header.tick < last_tick) {
            sample(acs, &st.header);
            ++published;
        }
        check(flexdyn_lockstep_answer_no_command(c) == FLEXDYN_OK, "answer",
              flexdyn_last_error(c));
    }
    while (flexdyn_poll_status(c, &status) == FLEXDYN_OK) have_status = 1;
    check(have_status && status.run_state == (uint32_t)FD_RUN_STATE_FINISHED, "the run finished",
          flexdyn_last_error(c));
    check(status.rejected_fsw_refused == 0, "the server refused no sample", "");
    printf("published %lu refusals %lu rejected_fsw_refused %lu\n", published, refusals,
           have_status ? (unsigned long)status.rejected_fsw_refused : 999ul);
    flexdyn_fsw_free(acs); /* before its client */
    flexdyn_client_free(c);
    return bad;
}
