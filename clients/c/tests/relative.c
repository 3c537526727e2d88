/*
 * relative.c - a fleet from C: two handles, one per vehicle of scenarios/formation.toml (the chief
 * answers as participant 1, the deputy as 2), and the deputy's RelativeStateMsg by the generated
 * calls (flexdyn_subscribe_relative_state with the chief's id as the name).
 *
 * Checks on every relative state: the ids, the key's chief, range = |r_dc_h| and
 * range_rate = r_dc_h . v_dc_h / |r_dc_h| (the transport theorem's omega x r is normal to r, so
 * the rate of the range seen in H is the inertial one), and at tick 0 the fleet's
 * hill_position_m = (3, -95, 2) m.
 *
 * Usage: relative <endpoint>; prints "relative states <n>, range at tick 0 <m> m" and exits 0
 * when every check held (each failure on stderr).
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

static flexdyn_client *open_as(const char *endpoint, const char *sc_id) {
    const char *connect[1];
    flexdyn_options opts;
    flexdyn_client *c = flexdyn_client_new();
    if (c == NULL) return NULL;
    connect[0] = endpoint;
    memset(&opts, 0, sizeof opts);
    opts.sc_id = sc_id;
    opts.connect = connect;
    opts.n_connect = 1;
    check(flexdyn_open(c, &opts) == FLEXDYN_OK, sc_id, c);
    return c;
}

int main(int argc, char **argv) {
    static fd_effector_state chief_effectors[FD_MAX_EFFECTORS], deputy_effectors[FD_MAX_EFFECTORS];
    flexdyn_client *chief, *deputy;
    fd_state_msg chief_st, deputy_st;
    fd_relative_state_msg rel;
    char name[FLEXDYN_NAME_CAP];
    unsigned long n_rel = 0;
    double range0 = -1.0;
    int rc_c, rc_d;
    if (argc != 2) return 2;
    chief = open_as(argv[1], "chief");
    deputy = open_as(argv[1], "deputy");
    if (chief == NULL || deputy == NULL || bad) return 1;
    check(flexdyn_subscribe_relative_state(deputy, "chief", 1024) == FLEXDYN_OK,
          "subscribe_relative_state", deputy);
    check(flexdyn_lockstep_join(chief, 1, 20000) == FLEXDYN_OK, "chief joins", chief);
    check(flexdyn_lockstep_join(deputy, 2, 20000) == FLEXDYN_OK, "deputy joins", deputy);
    if (bad) return 1;
    memset(&chief_st, 0, sizeof chief_st);
    chief_st.effectors = chief_effectors;
    chief_st.effectors_capacity = FD_MAX_EFFECTORS;
    memset(&deputy_st, 0, sizeof deputy_st);
    deputy_st.effectors = deputy_effectors;
    deputy_st.effectors_capacity = FD_MAX_EFFECTORS;
    for (;;) {
        rc_c = flexdyn_lockstep_wait(chief, &chief_st, 20000);
        rc_d = flexdyn_lockstep_wait(deputy, &deputy_st, 20000);
        if (rc_c == FLEXDYN_ENDED && rc_d == FLEXDYN_ENDED) break;
        if (rc_c != FLEXDYN_OK || rc_d != FLEXDYN_OK) {
            check(0, "both vehicles' ticks", rc_c != FLEXDYN_OK ? chief : deputy);
            break;
        }
        check(chief_st.header.tick == deputy_st.header.tick, "one tick for the fleet", chief);
        check(flexdyn_lockstep_answer_no_command(chief) == FLEXDYN_OK, "chief answers", chief);
        check(flexdyn_lockstep_answer_no_command(deputy) == FLEXDYN_OK, "deputy answers", deputy);
    }
    /* Every relative state of the run, in order (published after the deputy's state). */
    while (flexdyn_poll_relative_state(deputy, &rel, name, sizeof name) == FLEXDYN_OK) {
        double r = sqrt(rel.r_dc_h_m[0] * rel.r_dc_h_m[0] + rel.r_dc_h_m[1] * rel.r_dc_h_m[1] +
                        rel.r_dc_h_m[2] * rel.r_dc_h_m[2]);
        double rdot = (rel.r_dc_h_m[0] * rel.v_dc_h_m_s[0] + rel.r_dc_h_m[1] * rel.v_dc_h_m_s[1] +
                       rel.r_dc_h_m[2] * rel.v_dc_h_m_s[2]) /
                      r;
        check(strcmp(name, "chief") == 0, "the key names the chief", deputy);
        check(rel.header.seq == rel.header.tick && rel.header.tick == n_rel,
              "one relative state per tick, in order", deputy);
        check(rel.deputy_spacecraft_id == rel.header.spacecraft_id &&
                  rel.chief_spacecraft_id != rel.deputy_spacecraft_id,
              "the ids", deputy);
        check(fabs(rel.range_m - r) <= 1e-12 * r, "range = |r_dc_h|", deputy);
        check(fabs(rel.range_rate_m_s - rdot) <= 1e-9 * (1.0 + fabs(rdot)),
              "range rate = r . v / |r|", deputy);
        if (rel.header.tick == 0) {
            range0 = rel.range_m;
            check(fabs(rel.r_dc_h_m[0] - 3.0) < 1e-6 && fabs(rel.r_dc_h_m[1] + 95.0) < 1e-6 &&
                      fabs(rel.r_dc_h_m[2] - 2.0) < 1e-6,
                  "tick 0 is the fleet's hill_position_m (3, -95, 2)", deputy);
        }
        ++n_rel;
    }
    check(n_rel > 100, "relative states of the whole run", deputy);
    printf("relative states %lu, range at tick 0 %.6f m\n", n_rel, range0);
    flexdyn_client_free(chief);
    flexdyn_client_free(deputy);
    return bad;
}
