/*
 * pd_controller.c - a flexdyn control law in C: decode a StateMsg, compute the MRP PD torque
 * L = -K sigma_BN - P omega_BN (target sigma_RN = 0), encode the CommandMsg that answers it.
 *
 * The transport is yours. With zenoh-c (1.x) the loop around `answer()` is, in outline:
 *
 *     z_owned_config_t cfg;  z_config_default(&cfg);
 *     zc_config_insert_json5(z_loan_mut(cfg), "mode", "\"peer\"");
 *     zc_config_insert_json5(z_loan_mut(cfg), "connect/endpoints", "[\"tcp/127.0.0.1:7447\"]");
 *     zc_config_insert_json5(z_loan_mut(cfg), "listen/endpoints", "[]");
 *     zc_config_insert_json5(z_loan_mut(cfg), "scouting/multicast/enabled", "false");
 *     z_owned_session_t s;  z_open(&s, z_move(cfg), NULL);
 *     // publisher on fd_command_key(..., SENDER_ID) = "flexdyn/sc1/cmd/1"
 *     // subscriber on fd_state_key(...) = "flexdyn/sc1/tlm/state", whose callback does:
 *     //     z_owned_slice_t b; z_bytes_to_slice(z_sample_payload(sample), &b);
 *     //     size_t n = answer(z_slice_data(z_loan(b)), z_slice_len(z_loan(b)), out, sizeof out);
 *     //     if (n) { z_owned_bytes_t p; z_bytes_copy_from_buf(&p, out, n);
 *     //              z_publisher_put(z_loan(pub), z_move(p), NULL); }
 *     // lockstep: after the subscriber, declare the liveliness token
 *     //     z_liveliness_declare_token(z_loan(s), &token, fd_participant_key(...), NULL);
 *
 * This law reads only the state. A law that reads the IMU or a star tracker subscribes once to
 * "flexdyn/sc1/tlm/" followed by a double star, dispatches on the sample's key, and answers
 * tick k only when the state and every sensor sample due at tick k are in (which ones: the
 * flexdyn/sc1/config queryable); see ../README.md, "Lockstep flight code that reads sensors".
 *
 * zenoh-pico has the same shape (z_open, z_declare_subscriber, z_publisher_put,
 * z_liveliness_declare_token) with its own config keys (Z_CONFIG_CONNECT_KEY, and
 * Z_CONFIG_MULTICAST_SCOUTING_KEY = "false"). This project's tests do not build zenoh-c or
 * zenoh-pico: they compile and run this file's control law against the golden StateMsg
 * (proto/tests/c_header.rs), with the file standing in for the subscription.
 *
 * Usage here: pd_controller <StateMsg file>  - writes the CommandMsg bytes to stdout.
 */
#include <stdio.h>

#include "flexdyn_proto.h"

#define K_NM 100.0   /* attitude gain [N m per unit MRP] */
#define P_NMS 300.0  /* rate gain [N m s/rad] */
#define SENDER_ID 1u /* our lockstep participant id */

static fd_effector_state effectors[FD_MAX_EFFECTORS];
static uint64_t seq = 0;

/* The answer to one StateMsg: a Wrench command for its tick, or 0 if it does not decode. */
static size_t answer(const uint8_t *state_bytes, size_t len, uint8_t *out, size_t cap) {
    fd_state_msg st;
    fd_command_msg cmd;
    fd_error e;
    int i;
    memset(&st, 0, sizeof st);
    st.effectors = effectors;
    st.effectors_capacity = FD_MAX_EFFECTORS;
    e = fd_decode_state(state_bytes, len, &st);
    if (e.status != FD_OK) {
        fprintf(stderr, "undecodable StateMsg (status %d)\n", (int)e.status);
        return 0;
    }
    memset(&cmd, 0, sizeof cmd);
    /* Stamp: the state's spacecraft id, tick and time; our own sequence number. */
    cmd.header = fd_header_new(st.header.spacecraft_id, st.header.tick, st.header.sim_time_ns,
                               seq++);
    cmd.sender_id = SENDER_ID;
    cmd.kind = FD_COMMAND_WRENCH;
    for (i = 0; i < 3; ++i) {
        cmd.torque_b_nm[i] = -K_NM * st.sigma_bn[i] - P_NMS * st.omega_bn_b_rad_s[i];
        cmd.force_b_newton[i] = 0.0;
    }
    if (fd_validate_command(&cmd, 0).status != FD_OK) return 0; /* never send NaN */
    return fd_encode_command(&cmd, out, cap);
}

int main(int argc, char **argv) {
    static uint8_t in[FD_MAX_MESSAGE_BYTES];
    uint8_t out[FD_COMMAND_WRENCH_LEN];
    size_t len, n;
    FILE *f;
    if (argc != 2) {
        fprintf(stderr, "usage: %s <StateMsg file>\n", argv[0]);
        return 2;
    }
    f = fopen(argv[1], "rb");
    if (f == NULL) {
        fprintf(stderr, "cannot open %s\n", argv[1]);
        return 2;
    }
    len = fread(in, 1, sizeof in, f);
    fclose(f);
    n = answer(in, len, out, sizeof out);
    if (n == 0) return 1;
    fwrite(out, 1, n, stdout);
    return 0;
}
