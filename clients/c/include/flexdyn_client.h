/*
 * flexdyn_client.h - talk to a flexdyn server from C99 or C++ flight code.
 *
 * Link libflexdyn_client.a (or libflexdyn_client.so), built by `cargo build --release -p
 * flexdyn-client`. The library carries its own Zenoh (the Rust crate), so no zenoh-c is needed,
 * and it decodes and encodes with the same Rust codec as the server. Messages come out in the
 * structs of flexdyn_proto.h (proto/c/include): one C type per message, whichever way it was
 * decoded. Compile with -I proto/c/include -I clients/c/include; the link line is in the
 * top-level README, "Attaching flight code".
 *
 * Every function returns FLEXDYN_OK (0), FLEXDYN_EMPTY (1, a poll found nothing), FLEXDYN_ENDED
 * (2, a wait found nothing because the run is over) or a negative FLEXDYN_ERR_* code; after an
 * error, flexdyn_last_error(client) says what went wrong in one line. Nothing panics across the
 * boundary: a fault inside the library is FLEXDYN_ERR_INTERNAL.
 *
 * The end of a run (proto/README.md, "StatusMsg"): once its last frame is out, the server
 * publishes a last StatusMsg on flexdyn/<sc>/status whose run_state is FD_RUN_STATE_FINISHED,
 * _FAILED or _STOPPED. flexdyn_open subscribes to that key (its own subscription, separate from
 * flexdyn_subscribe_status) and remembers the first end it hears until flexdyn_close. From then
 * on every wait (flexdyn_lockstep_wait, flexdyn_wait_state, _imu, _star_tracker, _status,
 * flexdyn_wait_tick) still hands out what is queued, frames received before the end first, and
 * returns FLEXDYN_ENDED as soon as nothing more is queued (it looks every 20 ms and waits one
 * more 20 ms slice for a frame still in delivery), instead of waiting for its timeout. A flight loop ends on FLEXDYN_ENDED; flexdyn_run_ended says how the
 * run ended. Polls keep returning FLEXDYN_EMPTY.
 *
 * Threading contract
 *   - There is no global state: everything lives in a flexdyn_client handle.
 *   - A handle is NOT thread-safe: call it from one thread at a time (it may move between
 *     threads). Two handles are independent and may be used from two threads at once.
 *   - There are no callbacks. Samples are queued inside the library by Zenoh's own threads and
 *     handed over only when you call a poll or wait function, on your thread. Your code never
 *     runs on a library thread, so it needs no locking.
 *   - Each queue is a ring of `capacity` samples: if you fall behind, the oldest samples are
 *     dropped (the header's seq shows the gap), Zenoh is never blocked. In lockstep the server
 *     waits for your answer, so nothing is dropped.
 *   - Every wait takes a timeout in milliseconds and returns FLEXDYN_ERR_TIMEOUT when it passes:
 *     a lost server is an error code, never a hang. A run that ended is FLEXDYN_ENDED, at once.
 *
 * Lockstep (proto/README.md, "Lockstep protocol"): flexdyn_lockstep_join asks the server for
 * its configuration (which sensor samples each tick carries), subscribes once to
 * flexdyn/<sc>/tlm (all of it, so a tick's samples arrive in publication order), then declares
 * the liveliness token. flexdyn_lockstep_wait hands out the next complete tick (the state of tick
 * k and every sensor sample due at k); answer it with exactly one flexdyn_lockstep_answer_*.
 */
#ifndef FLEXDYN_CLIENT_H
#define FLEXDYN_CLIENT_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "flexdyn_proto.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------------------------ */
/* Return codes.                                                                               */

#define FLEXDYN_OK 0
#define FLEXDYN_EMPTY 1               /* a poll found nothing waiting (not an error) */
#define FLEXDYN_ENDED 2               /* a wait: the run ended and nothing more is queued (not an
                                       * error; flexdyn_run_ended says how) */
#define FLEXDYN_ERR_TIMEOUT (-1)      /* nothing came within the timeout: no server, or it left */
#define FLEXDYN_ERR_ARGUMENT (-2)     /* a null pointer, a bad id or endpoint, a non-finite value */
#define FLEXDYN_ERR_ZENOH (-3)        /* Zenoh refused (cannot open, declare or put) */
#define FLEXDYN_ERR_DECODE (-4)       /* a sample that is not a valid message (it is dropped) */
#define FLEXDYN_ERR_CAPACITY (-5)     /* your effectors array is too small (sample dropped) */
#define FLEXDYN_ERR_USAGE (-6)        /* out of order: not open, not subscribed, no tick held... */
#define FLEXDYN_ERR_CONFIG (-7)       /* the Zenoh config file or the served configuration */
#define FLEXDYN_ERR_INTERNAL (-8)     /* a fault inside the library (caught, never a crash) */
#define FLEXDYN_ERR_ABSENT (-9)       /* lockstep: that sensor has no sample in this tick */
#define FLEXDYN_ERR_CLOSED (-10)      /* the session was closed under a wait */

/* ------------------------------------------------------------------------------------------ */
/* The handle.                                                                                 */

typedef struct flexdyn_client flexdyn_client; /* opaque */

/* How to reach the server. Zero it (memset or = {0}) and set what you need. */
typedef struct {
    /* String spacecraft id of the keys (flexdyn/<sc_id>/...); NULL = "sc1". */
    const char *sc_id;
    /* Endpoints to connect to, e.g. "tcp/127.0.0.1:7447"; none = tcp/127.0.0.1:7447. */
    const char *const *connect;
    size_t n_connect;
    /* Endpoints to listen on; none = listen nowhere. */
    const char *const *listen;
    size_t n_listen;
    /* A standard Zenoh JSON5 file (e.g. the lab network's user/password and ACL); NULL = none.
     * connect/listen above replace its endpoints. Multicast scouting is always off. */
    const char *zenoh_config_file;
} flexdyn_options;

/* A new handle, not connected yet; NULL only if memory is exhausted. */
flexdyn_client *flexdyn_client_new(void);
/* Closes the session if open and frees the handle (NULL is accepted). */
void flexdyn_client_free(flexdyn_client *client);
/* The last error of this handle, one line, "" if none; valid until the next call on it. */
const char *flexdyn_last_error(const flexdyn_client *client);

/* Opens the Zenoh session: peer mode, loopback defaults, multicast scouting off. */
int flexdyn_open(flexdyn_client *client, const flexdyn_options *options);
/* Closes the session: undeclares every subscription and the lockstep token. The handle can be
 * opened again. Closing a closed handle is FLEXDYN_OK. */
int flexdyn_close(flexdyn_client *client);

/* Whether the server has said that the run ended (its last StatusMsg, heard by the subscription
 * every open makes): 1 once it has, and then *run_state_out = FD_RUN_STATE_FINISHED, _FAILED or
 * _STOPPED and *tick_out = the last tick the server stepped (either pointer may be NULL); 0
 * before, or when the session is not open; FLEXDYN_ERR_ARGUMENT for a NULL client. The first end
 * heard is kept until flexdyn_close. Never waits. */
int flexdyn_run_ended(flexdyn_client *client, int32_t *run_state_out, uint64_t *tick_out);

/* ------------------------------------------------------------------------------------------ */
/* Subscriptions: poll (FLEXDYN_OK or FLEXDYN_EMPTY) or wait (FLEXDYN_OK, FLEXDYN_ENDED once the
 * run has ended and nothing of that kind is queued, or FLEXDYN_ERR_TIMEOUT). One subscription
 * per kind; subscribing again replaces it. `capacity` = samples kept (>= 1). */

int flexdyn_subscribe_state(flexdyn_client *client, size_t capacity);
/* out->effectors / out->effectors_capacity are yours (FD_MAX_EFFECTORS always fits). */
int flexdyn_poll_state(flexdyn_client *client, fd_state_msg *out);
int flexdyn_wait_state(flexdyn_client *client, fd_state_msg *out, uint32_t timeout_ms);

/* The IMU, star tracker, status and every other message: flexdyn_client_messages.h (below),
 * e.g. flexdyn_subscribe_imu(client, name or NULL, capacity), flexdyn_poll_imu(client, &out,
 * name_out, name_cap), flexdyn_wait_imu(..., timeout_ms). A sensor's name_out (may be NULL)
 * receives its name, NUL-terminated: give it at least FLEXDYN_NAME_CAP bytes
 * (FLEXDYN_ERR_ARGUMENT otherwise, checked before a sample is taken). */
#define FLEXDYN_NAME_CAP 65

/* ------------------------------------------------------------------------------------------ */
/* The time service, flexdyn/<sc>/tlm/time: one fd_time_msg per published frame, before the
 * frame's sensor samples and state. Flight code driven by it (rate groups, a cFS tone adapter)
 * follows the simulation: its speed (--speed), its pauses and its steps. Subscribe first. */

int flexdyn_subscribe_time(flexdyn_client *client, size_t capacity);
/* The next tick's time message, waiting up to timeout_ms. FLEXDYN_ENDED once the run has ended
 * and none is queued. FLEXDYN_ERR_TIMEOUT when none came: the server is held (then flexdyn_now
 * says FD_RUN_STATE_PAUSED: the last tick published before the hold says so), gone, or slower
 * than the timeout. Never hangs. */
int flexdyn_wait_tick(flexdyn_client *client, fd_time_msg *out, uint32_t timeout_ms);
/* The newest time message received (every one queued is taken first), without waiting:
 * FLEXDYN_OK, or FLEXDYN_EMPTY before the first. */
int flexdyn_now(flexdyn_client *client, fd_time_msg *out);

/* ------------------------------------------------------------------------------------------ */
/* Operator control, on flexdyn/<sc>/operator (proto/README.md, "OperatorMsg"): action
 * FD_OPERATOR_PAUSE, _RESUME, _RUN_TICKS (lockstep: step `ticks` frames, then hold) or
 * _CHECKPOINT (protocol 12: save a checkpoint at tick `ticks`, 0 = the next boundary). `stamp` is
 * the header of any message of the server (its spacecraft_id is copied). On a lab network the
 * server's ACL lets only the operator's subject put there. */
int flexdyn_send_operator(flexdyn_client *client, const fd_header *stamp, uint32_t action,
                          uint64_t ticks);

/* ------------------------------------------------------------------------------------------ */
/* Commands, on flexdyn/<sc>/cmd/<sender_id>. `stamp` is the header of the state you answer
 * (its spacecraft_id, tick and sim_time_ns are copied; its seq is ignored): the library numbers
 * this handle's commands itself (seq 0, 1, 2, ...). Values must be finite
 * (FLEXDYN_ERR_ARGUMENT otherwise: the server would reject them). */

int flexdyn_send_wrench(flexdyn_client *client, uint32_t sender_id, const fd_header *stamp,
                        const double torque_b_nm[3], const double force_b_newton[3]);
int flexdyn_send_no_command(flexdyn_client *client, uint32_t sender_id, const fd_header *stamp);
/* inputs: n_inputs entries (may be NULL when n_inputs is 0). */
int flexdyn_send_actuators(flexdyn_client *client, uint32_t sender_id, const fd_header *stamp,
                           const double torque_b_nm[3], const double force_b_newton[3],
                           const fd_effector_input *inputs, size_t n_inputs);

/* ------------------------------------------------------------------------------------------ */
/* Lockstep participant.                                                                       */

/* Asks flexdyn/<sc>/config what the server runs (waiting up to timeout_ms for an answer),
 * subscribes to flexdyn/<sc>/tlm, then declares the token flexdyn/<sc>/participant/<sender_id>. */
int flexdyn_lockstep_join(flexdyn_client *client, uint32_t sender_id, uint32_t timeout_ms);
/* The next complete tick: its state into *state (effectors in your array). The tick is held
 * until the next wait; answer it once. A due sensor sample still missing 1 s after its state
 * (lost: never in a healthy lockstep run) is left out, and its getter says FLEXDYN_ERR_ABSENT.
 * FLEXDYN_ENDED (no tick held, *state untouched) once the server has said the run ended and
 * every tick received before is handed out: leave the loop, flexdyn_run_ended says how it ended.
 * The last tick of a run (duration_s * frame_hz) needs no answer; an answer to it is ignored. */
int flexdyn_lockstep_wait(flexdyn_client *client, fd_state_msg *state, uint32_t timeout_ms);
/* The sensors each tick carries, in configuration order (0 before a join), and the held tick's
 * sample of each: flexdyn_lockstep_imu_count / _name / flexdyn_lockstep_imu(client, index, &out),
 * and the same for star_tracker, magnetometer, css, fss and gps (flexdyn_client_messages.h).
 * Names stay valid until the next join, leave or close. A getter says FLEXDYN_ERR_ABSENT for a
 * sensor not due at this tick (or a sample lost). */
/* The one answer to the held tick (FLEXDYN_ERR_USAGE if there is none or it was answered). */
int flexdyn_lockstep_answer_wrench(flexdyn_client *client, const double torque_b_nm[3],
                                   const double force_b_newton[3]);
int flexdyn_lockstep_answer_no_command(flexdyn_client *client);
int flexdyn_lockstep_answer_actuators(flexdyn_client *client, const double torque_b_nm[3],
                                      const double force_b_newton[3],
                                      const fd_effector_input *inputs, size_t n_inputs);
/* Drops the token and the telemetry subscription (the server logs that the participant left). */
int flexdyn_lockstep_leave(flexdyn_client *client);

/* ------------------------------------------------------------------------------------------ */
/* The library's own decoders (the Rust codec, as on the server) into the same structs as
 * fd_decode_*: for bytes from elsewhere, e.g. a recording. */

int flexdyn_decode_state(flexdyn_client *client, const uint8_t *buf, size_t len, fd_state_msg *out);
int flexdyn_decode_imu(flexdyn_client *client, const uint8_t *buf, size_t len, fd_imu_msg *out);
int flexdyn_decode_star_tracker(flexdyn_client *client, const uint8_t *buf, size_t len,
                                fd_star_tracker_msg *out);
int flexdyn_decode_status(flexdyn_client *client, const uint8_t *buf, size_t len,
                          fd_status_msg *out);
int flexdyn_decode_time(flexdyn_client *client, const uint8_t *buf, size_t len, fd_time_msg *out);

/* sizeof the struct of a message as the library was built (FLEXDYN_STRUCT_*), to check that a
 * program and the library agree on flexdyn_proto.h; 0 for an unknown kind. */
#define FLEXDYN_STRUCT_HEADER 0
#define FLEXDYN_STRUCT_STATE 1
#define FLEXDYN_STRUCT_EFFECTOR_STATE 2
#define FLEXDYN_STRUCT_IMU 3
#define FLEXDYN_STRUCT_STAR_TRACKER 4
#define FLEXDYN_STRUCT_EFFECTOR_INPUT 5
#define FLEXDYN_STRUCT_STATUS 6
#define FLEXDYN_STRUCT_TIME 7
size_t flexdyn_struct_size(int which);

/* ------------------------------------------------------------------------------------------ */
/* Every message kind (protocol 10's sixteen), by its number FLEXDYN_KIND_*
 * (flexdyn_client_messages.h, generated from the wire table proto/schema/messages.toml). The
 * typed calls of that header - flexdyn_subscribe_magnetometer / _poll_ / _wait_, the same for
 * css, fss, gps, environment, fault_event and relative_state, the lockstep getters
 * flexdyn_lockstep_magnetometer_count / _name / flexdyn_lockstep_magnetometer (and css, fss,
 * gps), flexdyn_publish_fault_command and flexdyn_publish_operator - are built on these
 * byte-level calls, which you may also use directly. Keys: a kind whose key ends with a name
 * (a sensor's, or the chief's id for relative state, flexdyn/<your sc>/tlm/rel/<chief>) takes
 * that name, or NULL for every one. */

/* One subscription per kind; subscribing again replaces it. */
int flexdyn_subscribe_kind(flexdyn_client *client, int kind, const char *name, size_t capacity);
/* The next sample of `kind`, checked with the Rust codec (an undecodable one is dropped:
 * FLEXDYN_ERR_DECODE). *bytes points into the handle and stays valid until the next call on it.
 * name_out as in flexdyn_poll_imu (NULL, or FLEXDYN_NAME_CAP bytes). */
int flexdyn_poll_bytes(flexdyn_client *client, int kind, const uint8_t **bytes, size_t *len,
                       char *name_out, size_t name_cap);
int flexdyn_wait_bytes(flexdyn_client *client, int kind, const uint8_t **bytes, size_t *len,
                       char *name_out, size_t name_cap, uint32_t timeout_ms);
/* Puts an encoded message of a kind flight code or an operator sends (command, operator, fault
 * command) on its key: a command on flexdyn/<sc>/cmd/<its sender_id>. It is checked with the
 * Rust codec first: FLEXDYN_ERR_ARGUMENT, and nothing sent, for bytes the server would refuse
 * to decode; FLEXDYN_ERR_USAGE for a kind the server publishes, and for FLEXDYN_KIND_FSW, whose
 * key names its stream (publish it with flexdyn_fsw_declare and flexdyn_fsw_publish, below). */
int flexdyn_publish_bytes(flexdyn_client *client, int kind, const uint8_t *buf, size_t len);
/* Lockstep: the joined run's sensors of `kind` (IMU, star tracker, magnetometer, css, fss, GPS;
 * 0 for any other kind or before a join), their names, and the held tick's encoded sample of
 * entry `index` (FLEXDYN_ERR_ABSENT: not due at this tick, or lost). */
size_t flexdyn_lockstep_sensor_count(const flexdyn_client *client, int kind);
const char *flexdyn_lockstep_sensor_name(const flexdyn_client *client, int kind, size_t index);
int flexdyn_lockstep_sample_bytes(flexdyn_client *client, int kind, size_t index,
                                  const uint8_t **bytes, size_t *len);
/* For the typed calls: flexdyn_proto.h refused bytes the library handed out (fd_status, field);
 * records why and returns FLEXDYN_ERR_CAPACITY (your effectors array) or FLEXDYN_ERR_DECODE. */
int flexdyn_decode_failed(flexdyn_client *client, int kind, int fd_status, const char *field);
/* Records `message` as the last error and returns `code`. */
int flexdyn_fail(flexdyn_client *client, int code, const char *message);

#include "flexdyn_client_messages.h"

/* ------------------------------------------------------------------------------------------ */
/* Live faults, on flexdyn/<sc>/fault (proto/README.md, "FaultCommandMsg"). `stamp` is the header
 * of any message of the server (its spacecraft_id and tick are copied); `seq` numbers your fault
 * commands. The server checks a fault as it checks a [[faults]] entry and counts a refusal in
 * StatusMsg rejected.fault_refused; its FaultEventMsg (flexdyn_subscribe_fault_event) says when
 * it took effect. In lockstep, put it before your answer to tick at_tick - 1 for a deterministic
 * run. */

/* Injects `mode` (its code, proto/README.md "Fault modes") with `params` (2 values, unused ones
 * 0; NULL = both 0) on `target` ("imus.hub.gyro", at most FD_FAULT_TARGET_LEN bytes), on `axes`
 * (bit a for axis a + 1; 0 every axis), from boundary `at_tick` (FD_AT_NEXT_TICK: the next) for
 * `duration_ns` (0: until cleared), its generator seeded with `seed`. */
static inline int flexdyn_inject_fault(flexdyn_client *client, const fd_header *stamp,
                                       uint64_t seq, const char *target, uint32_t mode,
                                       const double params[2], uint32_t axes, uint64_t at_tick,
                                       uint64_t duration_ns, uint64_t seed) {
    fd_fault_command_msg m;
    size_t i;
    if (stamp == NULL || target == NULL)
        return flexdyn_fail(client, FLEXDYN_ERR_ARGUMENT, "stamp or target is a null pointer");
    memset(&m, 0, sizeof m);
    for (i = 0; target[i] != '\0'; ++i) {
        if (i == FD_FAULT_TARGET_LEN)
            return flexdyn_fail(client, FLEXDYN_ERR_ARGUMENT,
                                "target is longer than FD_FAULT_TARGET_LEN (128) bytes");
        m.target[i] = (uint8_t)target[i];
    }
    m.header = fd_header_new(stamp->spacecraft_id, stamp->tick, stamp->sim_time_ns, seq);
    m.action = FD_FAULT_INJECT;
    m.at_tick = at_tick;
    m.mode = mode;
    if (params != NULL) {
        m.params[0] = params[0];
        m.params[1] = params[1];
    }
    m.axes = axes;
    m.duration_ns = duration_ns;
    m.seed = seed;
    return flexdyn_publish_fault_command(client, &m);
}

/* Clears fault `fault_index` (a FaultEventMsg's) from boundary `at_tick` on. */
static inline int flexdyn_clear_fault(flexdyn_client *client, const fd_header *stamp,
                                      uint64_t seq, uint32_t fault_index, uint64_t at_tick) {
    fd_fault_command_msg m;
    if (stamp == NULL)
        return flexdyn_fail(client, FLEXDYN_ERR_ARGUMENT, "stamp is a null pointer");
    memset(&m, 0, sizeof m);
    m.header = fd_header_new(stamp->spacecraft_id, stamp->tick, stamp->sim_time_ns, seq);
    m.action = FD_FAULT_CLEAR;
    m.at_tick = at_tick;
    m.fault_index = fault_index;
    return flexdyn_publish_fault_command(client, &m);
}

/* ------------------------------------------------------------------------------------------ */
/* The flight code's own telemetry (protocol 10, proto/README.md "FswMsg"): stream <name> of the
 * served configuration's [[fsw_streams]] (its modes, events and values), published on
 * flexdyn/<sc>/fsw/<name> and recorded by the server beside the truth; never applied to the
 * physics. Declare a stream once, then for each sample: flexdyn_fsw_begin, the setters (by the
 * names the configuration declares: the library counts the words), flexdyn_fsw_publish.
 *
 *     flexdyn_fsw_stream *acs = NULL;
 *     if (flexdyn_fsw_declare(c, "acs", &acs, 5000) != FLEXDYN_OK) ... flexdyn_last_error(c)
 *     flexdyn_fsw_begin(acs, &st.header);                 (the state you answer)
 *     flexdyn_fsw_set_mode(acs, "detumble");
 *     flexdyn_fsw_set_f64(acs, "h_b_nms", h_b_nms, 3);
 *     if (flexdyn_fsw_publish(acs) != FLEXDYN_OK) ... flexdyn_fsw_last_error(acs)
 *     ...
 *     flexdyn_fsw_free(acs);                              (before flexdyn_client_free(c))
 *
 * Every call below but flexdyn_fsw_declare takes the stream handle and keeps its error message
 * in it, for flexdyn_fsw_last_error (a NULL stream is FLEXDYN_ERR_ARGUMENT). A refusal names
 * the stream and the field and changes nothing: the library refuses what the server would
 * count in StatusMsg rejected_fsw_refused, so a mistake is an error code here rather than a
 * sample lost there. A stream handle owns its Zenoh publisher and does not use its client
 * handle after the declaration: use it from one thread at a time, which may be another than
 * its client's. */

typedef struct flexdyn_fsw_stream flexdyn_fsw_stream; /* opaque */

/* Asks flexdyn/<sc>/config what the server runs (waiting up to timeout_ms, as
 * flexdyn_lockstep_join does), finds `stream` in its [[fsw_streams]] and declares the publisher
 * of flexdyn/<sc>/fsw/<stream>; *out is the new handle (NULL on any error). Errors go to the
 * client: FLEXDYN_ERR_ARGUMENT for a stream the configuration does not declare (the message
 * names the declared ones) or a name that is no key chunk, FLEXDYN_ERR_TIMEOUT when no server
 * answered, FLEXDYN_ERR_CONFIG for a reply the library cannot read. Declaring the same stream
 * twice gives two handles, each numbering its own samples: publish a stream from one. */
int flexdyn_fsw_declare(flexdyn_client *client, const char *stream, flexdyn_fsw_stream **out,
                        uint32_t timeout_ms);
/* Undeclares the publisher and frees the handle (NULL is accepted). */
void flexdyn_fsw_free(flexdyn_fsw_stream *stream);
/* The last error of this stream, one line, "" if none; valid until the next call on it. */
const char *flexdyn_fsw_last_error(const flexdyn_fsw_stream *stream);

/* Starts the sample of the tick `stamp` carries: the header of a server message (the state you
 * answer), whose spacecraft_id, tick and sim_time_ns are copied (its seq is ignored: the library
 * numbers each stream's samples 0, 1, 2, ...). A sample begun and not published is dropped.
 * FLEXDYN_ERR_ARGUMENT for another spacecraft's header; FLEXDYN_ERR_USAGE for a tick not after
 * the last one this stream published (the server records at most one sample per tick per
 * stream). In lockstep, publish the sample of tick k before your answer to tick k. */
int flexdyn_fsw_begin(flexdyn_fsw_stream *stream, const fd_header *stamp);
/* The setters of the sample begun (FLEXDYN_ERR_USAGE before flexdyn_fsw_begin). Each may be
 * called again to replace what it set; what is not called stays unset (its flag clear). */
/* The mode, by its name in the stream's `modes` (FD_FSW_MODE). */
int flexdyn_fsw_set_mode(flexdyn_fsw_stream *stream, const char *mode);
/* An event raised at this tick, by its name in the stream's `events`; up to FD_MAX_FSW_EVENTS
 * (8) per sample. */
int flexdyn_fsw_add_event(flexdyn_fsw_stream *stream, const char *event);
/* The attitude estimate q_BN, scalar first (FD_FSW_ESTIMATE); finite. */
int flexdyn_fsw_set_estimate(flexdyn_fsw_stream *stream, const double q_bn[4]);
/* The target attitude q_RN the flight code points B at, scalar first (FD_FSW_TARGET); finite. */
int flexdyn_fsw_set_target(flexdyn_fsw_stream *stream, const double q_rn[4]);
/* The variances of the estimate's attitude error about the body axes [rad^2]
 * (FD_FSW_COVARIANCE; needs an estimate in the same sample); finite. */
int flexdyn_fsw_set_variance(flexdyn_fsw_stream *stream, const double var_b_rad2[3]);
/* Declared value `name`: all its n elements (n = its declared `len`), of its declared type:
 * f64 (finite), i64, or bool (0 is false, any other int true). FLEXDYN_ERR_ARGUMENT for a name
 * the stream does not declare, another type or another length. */
int flexdyn_fsw_set_f64(flexdyn_fsw_stream *stream, const char *name, const double *v, size_t n);
int flexdyn_fsw_set_i64(flexdyn_fsw_stream *stream, const char *name, const int64_t *v, size_t n);
int flexdyn_fsw_set_bool(flexdyn_fsw_stream *stream, const char *name, const int *v, size_t n);
/* Encodes the sample begun with the library's Rust codec and puts it on the stream's key. Every
 * declared value must have been set: otherwise FLEXDYN_ERR_USAGE naming the values left out,
 * nothing is sent and the sample stays begun (set them and publish again); likewise for a
 * variance without an estimate. Once sent, the next sample needs a flexdyn_fsw_begin with a
 * later tick. FLEXDYN_ERR_ZENOH if the put failed (e.g. its client was closed). */
int flexdyn_fsw_publish(flexdyn_fsw_stream *stream);

#ifdef __cplusplus
}
#endif

#endif /* FLEXDYN_CLIENT_H */
