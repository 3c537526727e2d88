/*
 * send.c - the command functions outside lockstep. Connects to <endpoint>, waits for a state
 * (flexdyn_subscribe_state + flexdyn_wait_state), and answers it with a Wrench, a NoCommand and
 * an Actuators command from sender 7, each stamped from the state's header; then checks that a
 * non-finite torque and too many input values are refused before anything is sent.
 *
 * Usage: send <endpoint>; exits 0 when every call returned what it should.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "flexdyn_client.h"

static int expect(flexdyn_client *c, const char *what, int rc, int want) {
    if (rc != want) {
        fprintf(stderr, "%s: %d, expected %d (%s)\n", what, rc, want, flexdyn_last_error(c));
        return 1;
    }
    return 0;
}

int main(int argc, char **argv) {
    static fd_effector_state effectors[FD_MAX_EFFECTORS];
    const char *connect[1];
    flexdyn_options opts;
    flexdyn_client *c;
    fd_state_msg st;
    fd_effector_input in[2];
    double torque[3] = {0.5, -0.25, 0.125}, force[3] = {1.0, 2.0, 3.0};
    int bad = 0;
    if (argc != 2) return 2;
    c = flexdyn_client_new();
    if (c == NULL) return 2;
    connect[0] = argv[1];
    memset(&opts, 0, sizeof opts);
    opts.connect = connect;
    opts.n_connect = 1;
    bad |= expect(c, "open", flexdyn_open(c, &opts), FLEXDYN_OK);
    bad |= expect(c, "subscribe_state", flexdyn_subscribe_state(c, 4), FLEXDYN_OK);
    memset(&st, 0, sizeof st);
    st.effectors = effectors;
    st.effectors_capacity = FD_MAX_EFFECTORS;
    bad |= expect(c, "wait_state", flexdyn_wait_state(c, &st, 10000), FLEXDYN_OK);
    if (bad) return 1;

    bad |= expect(c, "send_wrench", flexdyn_send_wrench(c, 7, &st.header, torque, force),
                  FLEXDYN_OK);
    bad |= expect(c, "send_no_command", flexdyn_send_no_command(c, 7, &st.header), FLEXDYN_OK);
    memset(in, 0, sizeof in);
    in[0].effector_index = 3;
    in[0].n_values = 1;
    in[0].values[0] = -0.0625;
    in[1].effector_index = 5;
    in[1].n_values = 2;
    in[1].values[0] = 1.5;
    in[1].values[1] = 2.5;
    bad |= expect(c, "send_actuators",
                  flexdyn_send_actuators(c, 7, &st.header, torque, force, in, 2), FLEXDYN_OK);

    /* Refused before sending: the server would reject them. */
    torque[1] = NAN;
    bad |= expect(c, "NaN torque", flexdyn_send_wrench(c, 7, &st.header, torque, force),
                  FLEXDYN_ERR_ARGUMENT);
    if (strstr(flexdyn_last_error(c), "torque_b_nm[1] = NaN is not finite") == NULL) {
        fprintf(stderr, "NaN torque message: %s\n", flexdyn_last_error(c));
        bad = 1;
    }
    torque[1] = 0.0;
    in[1].n_values = 33; /* MAX_EFFECTOR_VALUES + 1 */
    bad |= expect(c, "33 values", flexdyn_send_actuators(c, 7, &st.header, torque, force, in, 2),
                  FLEXDYN_ERR_ARGUMENT);
    bad |= expect(c, "null stamp", flexdyn_send_no_command(c, 7, NULL), FLEXDYN_ERR_ARGUMENT);
    bad |= expect(c, "close", flexdyn_close(c), FLEXDYN_OK);
    bad |= expect(c, "send after close", flexdyn_send_no_command(c, 7, &st.header),
                  FLEXDYN_ERR_USAGE);
    flexdyn_client_free(c);
    return bad;
}
