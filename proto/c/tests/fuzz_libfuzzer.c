/*
 * A libFuzzer target over every decoder of flexdyn_proto.h, built with AddressSanitizer and
 * UndefinedBehaviorSanitizer (proto/tests/c_libfuzzer.rs, `libfuzzer_with_sanitizers_finds_nothing`).
 *
 * Beyond "no crash, no memory error, no undefined behaviour", each input is held to the
 * header's own contract; a breach aborts, which libFuzzer reports as a crash with the input:
 * - a decoder that accepts the bytes gives a message its encoder writes back byte for byte
 *   (the same length, the same bytes), and whose fields marked finite pass fd_validate_*;
 * - a decoder that refuses them reports a reason from fd_status with `actual` = the buffer's
 *   length, `needed` above it for FD_ERR_LENGTH and below it for FD_ERR_TRAILING_BYTES, and a
 *   named field for FD_ERR_NON_FINITE and FD_ERR_MALFORMED;
 * - the header decoder accepts exactly the buffers whose first 30 bytes it can read under the
 *   size and version rules.
 */
#include <stdlib.h>
#include <string.h>

#include "flexdyn_proto.h"

static fd_effector_state effectors[FD_MAX_EFFECTORS];
static fd_effector_input inputs[FD_MAX_EFFECTORS];
static uint8_t out[FD_MAX_MESSAGE_BYTES];

static void check_refusal(fd_error e, size_t size) {
    if (e.status < FD_ERR_LENGTH || e.status > FD_ERR_CAPACITY) abort();
    if (e.actual != size) abort();
    if (e.status == FD_ERR_LENGTH && e.needed <= size) abort();
    if (e.status == FD_ERR_TRAILING_BYTES && e.needed >= size) abort();
    if ((e.status == FD_ERR_NON_FINITE || e.status == FD_ERR_MALFORMED) &&
        (e.field == NULL || e.field[0] == '\0'))
        abort();
    /* Every caller array here holds FD_MAX_EFFECTORS: a capacity refusal is a bug. */
    if (e.status == FD_ERR_CAPACITY) abort();
}

static void check_round_trip(size_t n, const uint8_t *data, size_t size) {
    if (n != size || memcmp(out, data, size) != 0) abort();
}

#define ROUND_TRIP(kind, type, setup)                                                            \
    do {                                                                                         \
        type m;                                                                                  \
        fd_error e;                                                                              \
        memset(&m, 0, sizeof m);                                                                 \
        setup;                                                                                   \
        e = fd_decode_##kind(data, size, &m);                                                    \
        if (e.status == FD_OK)                                                                   \
            check_round_trip(fd_encode_##kind(&m, out, sizeof out), data, size);                 \
        else                                                                                     \
            check_refusal(e, size);                                                              \
    } while (0)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    fd_header h;
    fd_error e = fd_decode_header(data, size, &h);
    if (e.status == FD_OK) {
        if (size < FD_HEADER_LEN || size > FD_MAX_MESSAGE_BYTES || h.protocol_version != FD_PROTOCOL_VERSION) abort();
    } else if (size >= FD_HEADER_LEN && size <= FD_MAX_MESSAGE_BYTES &&
               data[0] == (FD_PROTOCOL_VERSION & 0xFFu) && data[1] == (FD_PROTOCOL_VERSION >> 8)) {
        abort();
    }
    ROUND_TRIP(state, fd_state_msg, (m.effectors = effectors, m.effectors_capacity = FD_MAX_EFFECTORS));
    ROUND_TRIP(imu, fd_imu_msg, (void)0);
    ROUND_TRIP(star_tracker, fd_star_tracker_msg, (void)0);
    ROUND_TRIP(magnetometer, fd_magnetometer_msg, (void)0);
    ROUND_TRIP(css, fd_css_msg, (void)0);
    ROUND_TRIP(fss, fd_fss_msg, (void)0);
    ROUND_TRIP(gps, fd_gps_msg, (void)0);
    ROUND_TRIP(time, fd_time_msg, (void)0);
    ROUND_TRIP(environment, fd_environment_msg, (void)0);
    ROUND_TRIP(operator, fd_operator_msg, (void)0);
    ROUND_TRIP(fault_event, fd_fault_event_msg, (void)0);
    ROUND_TRIP(relative_state, fd_relative_state_msg, (void)0);
    ROUND_TRIP(status, fd_status_msg, (void)0);
    ROUND_TRIP(fsw, fd_fsw_msg, (void)0);
    {
        fd_command_msg m;
        memset(&m, 0, sizeof m);
        m.inputs = inputs;
        m.inputs_capacity = FD_MAX_EFFECTORS;
        e = fd_decode_command(data, size, &m);
        if (e.status == FD_OK) {
            if (fd_validate_command(&m, size).status != FD_OK) abort();
            check_round_trip(fd_encode_command(&m, out, sizeof out), data, size);
        } else {
            check_refusal(e, size);
        }
    }
    {
        fd_fault_command_msg m;
        memset(&m, 0, sizeof m);
        e = fd_decode_fault_command(data, size, &m);
        if (e.status == FD_OK) {
            if (fd_validate_fault_command(&m, size).status != FD_OK) abort();
            check_round_trip(fd_encode_fault_command(&m, out, sizeof out), data, size);
        } else {
            check_refusal(e, size);
        }
    }
    return 0;
}
