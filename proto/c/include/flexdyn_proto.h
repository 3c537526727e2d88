/*
 * flexdyn_proto.h - the flexdyn wire protocol (version 9) for C99 and C++ flight code.
 *
 * Header-only: include it and call fd_decode_* / fd_encode_*. No allocation, no I/O, no
 * global state. Bytes are assembled one by one (little-endian on the wire), never cast to a
 * struct, so it is correct on big-endian hosts too. The byte tables are in proto/README.md;
 * this file follows them and the decoder rules there in the same order, with the same error
 * reasons as the Rust crate's DecodeError:
 *
 *   1. more than FD_MAX_MESSAGE_BYTES                      -> FD_ERR_TOO_LARGE
 *   2. fewer than 2 bytes                                   -> FD_ERR_LENGTH
 *      first two bytes (u16 LE) != FD_PROTOCOL_VERSION      -> FD_ERR_UNKNOWN_VERSION
 *   3. total length from the layout (fixed, tag, walked counts; every count bounded first)
 *      buffer shorter                                       -> FD_ERR_LENGTH (needed = length
 *                                                              implied by the counts read)
 *      unknown command tag, count above its maximum         -> FD_ERR_MALFORMED
 *      buffer longer                                        -> FD_ERR_TRAILING_BYTES
 *   4. fields in wire order: an enum tag out of range or a bool byte other than 0/1
 *                                                           -> FD_ERR_MALFORMED
 *   5. CommandMsg: a non-finite torque, force or input value (in that order)
 *      FaultCommandMsg: a non-finite params value (since protocol 8)
 *                                                           -> FD_ERR_NON_FINITE (field named)
 *
 * Decoders write into caller storage; a StateMsg's effectors and an Actuators command's inputs
 * go into arrays the caller provides (capacity given), FD_ERR_CAPACITY if they do not fit (a C-only
 * reason, checked after the wire rules). Compile with -std=c99 -Wall -Wextra -pedantic.
 *
 * C++: the same file compiles as C++ (C++98 on; nullptr from C++11) without a warning under the
 * stricter lints C++ teams use: -Wold-style-cast, -Wzero-as-null-pointer-constant (clang, and
 * compilers whose NULL is a plain 0), -Wuseless-cast (g++), -Wconversion, -Wsign-conversion.
 * Casts are written FD_CAST(type, value), which is static_cast in C++; null pointers FD_NULL,
 * which is nullptr from C++11 on. Every function is static inline (internal linkage, nothing to
 * link), so there is no extern "C" block: it would add nothing, and g++ does not apply
 * -Wold-style-cast inside one, which would hide regressions from the C++ check.
 *
 * Lockstep flight code: compute the answer to tick k from the StateMsg of tick k together with
 * every sensor sample due at tick k. proto/README.md, "Lockstep protocol", says how: one
 * subscriber on all of flexdyn/<sc>/tlm (the key expression ending in a double star), and the
 * sensors and their rates from the flexdyn/<sc>/config queryable.
 */
#ifndef FLEXDYN_PROTO_H
#define FLEXDYN_PROTO_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* Casts and null pointers that suit both languages (see the C++ note above). */
#ifdef __cplusplus
#define FD_CAST(type, value) (static_cast<type>(value))
#if __cplusplus >= 201103L || (defined(_MSVC_LANG) && _MSVC_LANG >= 201103L)
#define FD_NULL nullptr
#else
#define FD_NULL NULL
#endif
#else
#define FD_CAST(type, value) ((type)(value))
#define FD_NULL NULL
#endif

/* ------------------------------------------------------------------------------------------ */
/* Constants (proto/README.md).                                                                */

#define FD_PROTOCOL_VERSION 9u
#define FD_HEADER_LEN 30u
#define FD_STATE_FIXED_LEN 327u
#define FD_STATE_EFFECTOR_COUNT_OFFSET 319u
#define FD_EFFECTOR_STATE_FIXED_LEN 22u
#define FD_EFFECTOR_INPUT_FIXED_LEN 12u
#define FD_IMU_LEN 127u
#define FD_STAR_TRACKER_LEN 64u
#define FD_MAGNETOMETER_LEN 55u
#define FD_COMMAND_KIND_OFFSET 34u
#define FD_COMMAND_WRENCH_LEN 86u
#define FD_COMMAND_NO_COMMAND_LEN 38u
#define FD_COMMAND_ACTUATORS_FIXED_LEN 94u
#define FD_STATUS_LEN 235u
#define FD_TIME_LEN 122u
/* Sun sensors (protocol 6) */
#define FD_CSS_LEN 159u
#define FD_FSS_LEN 47u
#define FD_MAX_CSS_DETECTORS 16u
#define FD_TIME_CUC_OFFSET 98u
#define FD_OPERATOR_LEN 42u /* since protocol 6 */
#define FD_ENVIRONMENT_LEN 368u
#define FD_GPS_LEN 147u /* since protocol 7 */
/* Fault injection (protocol 8) */
#define FD_FAULT_EVENT_LEN 199u
#define FD_FAULT_COMMAND_LEN 214u
#define FD_FAULT_TARGET_LEN 128u
#define FD_MAX_STATUS_FAULTS 256u
#define FD_RELATIVE_STATE_LEN 102u /* since protocol 9 */
#define FD_MAX_EFFECTORS 1024u
#define FD_MAX_EFFECTOR_VALUES 8u
#define FD_MAX_MESSAGE_BYTES 65536u

/* Command kinds (CommandMsg tag at offset 34). */
#define FD_COMMAND_WRENCH 0u
#define FD_COMMAND_NO_COMMAND 1u
#define FD_COMMAND_ACTUATORS 2u

/* Effector kinds (EffectorState.kind). */
#define FD_EFFECTOR_PANEL_PAIR 1u
#define FD_EFFECTOR_REACTION_WHEEL 2u
#define FD_EFFECTOR_MAGNETORQUER 3u
#define FD_EFFECTOR_THRUSTER 4u

/* StateMsg.command_flags */
#define FD_COMMAND_FLAG_STALE 0x01u
#define FD_COMMAND_FLAG_ZEROED_BY_POLICY 0x02u
#define FD_COMMAND_FLAG_NO_COMMAND_YET 0x04u
/* ImuMsg.saturation_flags */
#define FD_SATURATION_GYRO_RATE 0x01u
#define FD_SATURATION_ACCEL 0x02u
#define FD_SATURATION_DTHETA 0x04u
#define FD_SATURATION_DV 0x08u
/* StarTrackerMsg.status_flags */
#define FD_STAR_TRACKER_SUN_EXCLUSION 0x01u
#define FD_STAR_TRACKER_RATE_LIMIT 0x02u
#define FD_MAGNETOMETER_AXIS_1 0x01u
#define FD_MAGNETOMETER_AXIS_2 0x02u
#define FD_MAGNETOMETER_AXIS_3 0x04u
/* FssMsg.flags (protocol 6) */
#define FD_FSS_VALID 0x01u  /* the angles are a measurement (IN_FOV and SUNLIT); else both 0 */
#define FD_FSS_IN_FOV 0x02u /* the Sun is inside the field-of-view cone */
#define FD_FSS_SUNLIT 0x04u /* the shadow factor is at least the sensor's threshold */
/* TimeMsg.flags (protocol 5) */
#define FD_TIME_EPOCH_VALID 0x01u /* calendar fields set; clear: they are all zero */
#define FD_TIME_TONE 0x02u        /* the 1 Hz tone: first frame at or after a whole second */
#define FD_TIME_LEAP_SECOND 0x04u /* inside an inserted leap second (UTC second = 60) */
/* TimeMsg.cuc_tai[0]: CCSDS 301.0-B-4 CUC P-field, TAI 1958 epoch, 4 coarse + 3 fine octets. */
#define FD_CUC_PFIELD_TAI_4_3 0x1Fu
/* EnvironmentMsg.flags (protocol 6): which models are on */
#define FD_ENVIRONMENT_EPOCH_VALID 0x01u /* tai_ns_1958 set */
#define FD_ENVIRONMENT_MAGNETIC 0x02u    /* b_n_t, b_b_t */
#define FD_ENVIRONMENT_SUN 0x04u         /* sun_n, sun_b */
#define FD_ENVIRONMENT_MOON 0x08u        /* moon_n */
#define FD_ENVIRONMENT_SHADOW 0x10u      /* shadow_factor, eclipse */
#define FD_ENVIRONMENT_ATMOSPHERE 0x20u  /* density_kg_m3 */
/* EnvironmentMsg.eclipse */
#define FD_ECLIPSE_SUNLIT 0u
#define FD_ECLIPSE_PENUMBRA 1u
#define FD_ECLIPSE_UMBRA 2u
/* GpsMsg.flags (protocol 7) */
#define FD_GPS_FIX 0x01u      /* a fix: the time and the configured frames' fields are measured */
#define FD_GPS_ECEF 0x02u     /* r_be_e_m, v_be_e_m_s are configured output */
#define FD_GPS_INERTIAL 0x04u /* r_bn_n_m, v_bn_n_m_s are configured output */
/* EffectorState.flags of a reaction wheel */
#define FD_WHEEL_TORQUE_LIMITED 0x1u
#define FD_WHEEL_SPEED_LIMITED 0x2u
/* EffectorState.flags of a magnetorquer */
#define FD_MAGNETORQUER_SATURATED 0x1u
/* EffectorState.flags of a thruster */
#define FD_THRUSTER_FIRING 0x1u
#define FD_THRUSTER_BELOW_MIN_ON_TIME 0x2u
#define FD_THRUSTER_COMMAND_CLIPPED 0x4u

/* StatusMsg enums */
#define FD_MODE_REAL_TIME 0u
#define FD_MODE_LOCKSTEP 1u
#define FD_MODE_BATCH 2u
#define FD_RUN_STATE_STARTING 0u
#define FD_RUN_STATE_RUNNING 1u
#define FD_RUN_STATE_STOPPING 2u
#define FD_RUN_STATE_FINISHED 3u
#define FD_RUN_STATE_FAILED 4u
#define FD_RUN_STATE_STOPPED 5u
#define FD_RUN_STATE_PAUSED 6u /* since protocol 5: holding at a tick on an operator's request */
#define FD_STALE_POLICY_HOLD 0u
#define FD_STALE_POLICY_ZERO 1u
/* OperatorMsg.action (since protocol 6) */
#define FD_OPERATOR_PAUSE 0u
#define FD_OPERATOR_RESUME 1u
#define FD_OPERATOR_RUN_TICKS 2u
/* FaultEventMsg.source (since protocol 8) */
#define FD_FAULT_SOURCE_CONFIG 0u
#define FD_FAULT_SOURCE_LIVE 1u
#define FD_FAULT_SOURCE_RANDOM 2u
/* FaultCommandMsg.action (since protocol 8) */
#define FD_FAULT_INJECT 0u
#define FD_FAULT_CLEAR 1u
/* FaultCommandMsg.at_tick: at the next frame boundary. */
#define FD_AT_NEXT_TICK UINT64_MAX
/* CommandStatus.last_command_tick / command_age_ns before any command. */
#define FD_NO_COMMAND UINT64_MAX

/* ------------------------------------------------------------------------------------------ */
/* Errors: the Rust DecodeError variants, plus FD_ERR_CAPACITY for caller storage.              */

typedef enum {
    FD_OK = 0,
    FD_ERR_LENGTH = 1,          /* needed, actual */
    FD_ERR_TRAILING_BYTES = 2,  /* expected (in needed), actual */
    FD_ERR_TOO_LARGE = 3,       /* actual; max = FD_MAX_MESSAGE_BYTES */
    FD_ERR_UNKNOWN_VERSION = 4, /* found_version */
    FD_ERR_NON_FINITE = 5,      /* field */
    FD_ERR_MALFORMED = 6,       /* field: what was wrong */
    FD_ERR_CAPACITY = 7         /* needed: the count that did not fit the caller's array */
} fd_status;

typedef struct {
    fd_status status;
    size_t needed;          /* LENGTH: total length required; TRAILING_BYTES: message length */
    size_t actual;          /* the buffer length */
    uint16_t found_version; /* UNKNOWN_VERSION */
    const char *field;      /* NON_FINITE: the field path as in Rust; MALFORMED: a reason */
} fd_error;

/* ------------------------------------------------------------------------------------------ */
/* Messages.                                                                                   */

typedef struct {
    uint16_t protocol_version;
    uint32_t spacecraft_id;
    uint64_t tick;
    uint64_t sim_time_ns;
    uint64_t seq;
} fd_header;

typedef struct {
    uint16_t kind;
    uint32_t flags;
    uint64_t n_states;
    double states[FD_MAX_EFFECTOR_VALUES];
    uint64_t n_outputs;
    double outputs[FD_MAX_EFFECTOR_VALUES];
} fd_effector_state;

typedef struct {
    fd_header header;
    double sigma_bn[3];
    double q_bn[4]; /* scalar first */
    double omega_bn_b_rad_s[3];
    double omega_dot_bn_b_rad_s2[3];
    double r_bn_n_m[3];
    double v_bn_n_m_s[3];
    double nongrav_accel_bn_n_m_s2[3];
    double orb_energy_j;
    double rot_energy_j;
    double orb_ang_mom_n[3];
    double rot_ang_mom_c_n[3];
    double torque_b_nm[3];    /* wrench_applied */
    double force_b_newton[3]; /* wrench_applied */
    uint8_t command_flags;
    uint64_t n_effectors;
    fd_effector_state *effectors; /* caller storage */
    size_t effectors_capacity;
} fd_state_msg;

typedef struct {
    fd_header header;
    double omega_p_rad_s[3];
    double accel_p_m_s2[3];
    double dtheta_p_rad[3];
    double dv_p_m_s[3];
    uint8_t saturation_flags;
} fd_imu_msg;

typedef struct {
    fd_header header;
    double q_cn[4]; /* scalar first */
    uint8_t valid;  /* 0 or 1 */
    uint8_t status_flags;
} fd_star_tracker_msg;

/* A cFE CFE_TIME_SysTime_t: seconds and subseconds in units of 2^-32 s. */
typedef struct {
    uint32_t seconds;
    uint32_t subseconds;
} fd_sys_time;

/* The time service, flexdyn/<sc>/tlm/time, one per frame before its sensors and state. */
typedef struct {
    fd_header header;     /* tick, sim_time_ns, seq (= tick) */
    uint32_t run_state;   /* FD_RUN_STATE_RUNNING, _PAUSED (held at this tick), ... */
    uint32_t mode;        /* FD_MODE_* */
    uint8_t flags;        /* FD_TIME_* */
    uint64_t frame_ns;    /* the frame period */
    double speed;         /* real time: --speed; lockstep and batch: 0 */
    uint64_t tai_ns_1958; /* TAI since 1958-01-01T00:00:00 TAI */
    uint16_t utc_year;
    uint8_t utc_month, utc_day, utc_hour, utc_minute, utc_second; /* second 60 in a leap second */
    uint32_t utc_nanosecond;
    int32_t tai_minus_utc_s; /* leap-second count */
    uint32_t gps_week;
    uint64_t gps_ns_of_week;
    uint64_t met_ns;         /* mission elapsed time: since the epoch (sim time 0) */
    uint8_t cuc_tai[8];      /* P-field, 4 coarse, 3 fine octets, big-endian (CCSDS order) */
    fd_sys_time tone_met;    /* MET at the most recent tone */
    fd_sys_time tone_tai;    /* TAI (1958) at the most recent tone */
} fd_time_msg;

/* One environment source's torque about B and force at B, B components (torque first). */
typedef struct {
    double torque_b_nm[3];
    double force_b_newton[3];
} fd_source_wrench;

/* The environment at the spacecraft, flexdyn/<sc>/tlm/env, at [environment] telemetry_rate_hz
 * (protocol 6). Every value refers to header.tick. */
typedef struct {
    fd_header header;
    uint64_t tai_ns_1958; /* 0 without an epoch */
    uint8_t flags;        /* FD_ENVIRONMENT_* */
    uint8_t eclipse;      /* FD_ECLIPSE_* */
    double b_n_t[3];      /* T, N components */
    double b_b_t[3];      /* T, B components */
    double sun_n[3];      /* unit vector B -> Sun, N components */
    double sun_b[3];      /* the same, B components */
    double moon_n[3];     /* unit vector B -> Moon, N components */
    double shadow_factor; /* visible fraction of the solar disc */
    double density_kg_m3;
    fd_source_wrench gravity_gradient, drag, solar_pressure, residual_dipole;
} fd_environment_msg;

/* A GPS receiver's solution, flexdyn/<sc>/tlm/gps/<name> (protocol 7). header.sim_time_ns is
 * the publication time; the measurement is valid at valid_sim_time_ns (the latency earlier).
 * Without FD_GPS_FIX every number is 0; each frame's fields are 0 unless its flag is set. */
typedef struct {
    fd_header header;
    uint64_t valid_sim_time_ns;
    uint32_t gps_week;          /* since 1980-01-06, not modulo 1024 */
    double gps_seconds_of_week; /* s, GPS = TAI - 19 s */
    double r_be_e_m[3];         /* m, position of B from the Earth's centre, ECEF */
    double v_be_e_m_s[3];       /* m/s, velocity relative to ECEF, ECEF components */
    double r_bn_n_m[3];         /* m, position in N */
    double v_bn_n_m_s[3];       /* m/s, inertial velocity, N components */
    uint8_t flags;              /* FD_GPS_* */
} fd_gps_msg;

typedef struct {
    fd_header header;
    double b_s_t[3]; /* T, sensor frame S */
    uint8_t saturation_flags;
} fd_magnetometer_msg;

typedef struct {
    fd_header header;
    uint8_t detector_count;                 /* K <= FD_MAX_CSS_DETECTORS */
    double readings[FD_MAX_CSS_DETECTORS]; /* array output unit; entries K.. are 0 */
} fd_css_msg;

typedef struct {
    fd_header header;
    double alpha_rad; /* atan2(s1, s3), s the Sun direction in the sensor frame F */
    double beta_rad;  /* atan2(s2, s3) */
    uint8_t flags;    /* FD_FSS_* */
} fd_fss_msg;

typedef struct {
    uint32_t effector_index;
    uint64_t n_values;
    double values[FD_MAX_EFFECTOR_VALUES];
} fd_effector_input;

typedef struct {
    fd_header header;
    uint32_t sender_id;
    uint32_t kind;            /* FD_COMMAND_* */
    double torque_b_nm[3];    /* WRENCH, ACTUATORS */
    double force_b_newton[3]; /* WRENCH, ACTUATORS */
    uint64_t n_inputs;        /* ACTUATORS */
    fd_effector_input *inputs; /* caller storage */
    size_t inputs_capacity;
} fd_command_msg;

typedef struct {
    fd_header header;
    uint32_t mode;
    uint32_t run_state;
    uint64_t lateness_p50_ns;
    uint64_t lateness_p99_ns;
    uint64_t lateness_max_ns;
    uint64_t overrun_count;
    uint64_t frames_skipped;
    uint64_t last_command_tick;
    uint64_t command_age_ns;
    uint8_t command_stale;
    uint32_t stale_policy;
    uint64_t rejected_malformed;
    uint64_t rejected_bad_version;
    uint64_t rejected_non_finite;
    uint64_t rejected_wrong_spacecraft;
    uint64_t rejected_stale_tick;
    uint64_t rejected_unknown_sender;
    uint64_t rejected_bad_effector_input;
    uint64_t rejected_wrong_identity; /* since protocol 4: sender_id is not the one its key names */
    uint64_t rejected_operator_refused; /* since protocol 6: an OperatorMsg not applied */
    uint64_t rejected_fault_refused; /* since protocol 8: a FaultCommandMsg not applied */
    uint64_t commands_dropped;
    uint64_t wall_time_unix_ns;
    uint64_t faults_active;          /* since protocol 8: faults active at header.tick */
    uint64_t faults_active_bits[4];  /* bit i%64 of word i/64: fault index i active (i < 256) */
} fd_status_msg;

/* A fault's activation or clearance, flexdyn/<sc>/tlm/fault (since protocol 8). */
typedef struct {
    fd_header header;   /* tick: the boundary where the change is seen; seq: event counter */
    uint32_t fault_index; /* [[faults]] entry, or configured count + live order */
    uint32_t source;    /* FD_FAULT_SOURCE_* */
    uint32_t mode;      /* the mode code, proto/README.md "Fault modes" */
    uint8_t active;     /* 1 activated, 0 cleared */
    uint64_t edge_ns;   /* sim time the activation began / the clearance took effect */
    uint32_t axes;      /* bit a: 1-based axis a + 1; 0: every axis */
    double params[2];   /* the mode's parameters in its row's order */
    uint8_t target[FD_FAULT_TARGET_LEN]; /* UTF-8, NUL-padded */
} fd_fault_event_msg;

/* A fleet deputy's state relative to its chief, flexdyn/<deputy>/tlm/rel/<chief> (since
 * protocol 9). Both at their centres of mass; H is the chief's Hill frame (x radial, z along
 * the orbit normal, y along-track). header.spacecraft_id is the deputy's; seq = tick. */
typedef struct {
    fd_header header;
    uint32_t chief_spacecraft_id;
    uint32_t deputy_spacecraft_id;
    double r_dc_h_m[3];   /* m, deputy relative to chief, H components */
    double v_dc_h_m_s[3]; /* m/s, its rate seen in H, H components */
    double range_m;       /* m */
    double range_rate_m_s; /* m/s, negative while closing */
} fd_relative_state_msg;

/* A live fault command, flexdyn/<sc>/fault (since protocol 8). */
typedef struct {
    fd_header header;   /* spacecraft_id must be the server's; seq: the sender's counter */
    uint32_t action;    /* FD_FAULT_INJECT or FD_FAULT_CLEAR */
    uint64_t at_tick;   /* boundary at which it applies; FD_AT_NEXT_TICK: the next one */
    uint32_t fault_index; /* CLEAR: the fault to clear; INJECT: 0 */
    uint32_t mode;      /* INJECT: the mode code */
    double params[2];   /* INJECT: the mode's parameters (finite) */
    uint32_t axes;      /* INJECT: bit a: 1-based axis a + 1; 0: every axis */
    uint64_t duration_ns; /* INJECT: 0 until cleared */
    uint64_t seed;      /* INJECT: generator seed (noise, spikes) */
    uint8_t target[FD_FAULT_TARGET_LEN]; /* INJECT: "imus.hub.gyro", UTF-8, NUL-padded */
} fd_fault_command_msg;

/* An operator's command, flexdyn/<sc>/operator (since protocol 6). */
typedef struct {
    fd_header header; /* spacecraft_id must be the server's; seq: the operator's counter */
    uint32_t action;  /* FD_OPERATOR_* */
    uint64_t ticks;   /* RUN_TICKS: frames to step before holding (>= 1); others: 0 */
} fd_operator_msg;

/* ------------------------------------------------------------------------------------------ */
/* Byte helpers (little-endian, assembled byte by byte).                                       */

static inline uint16_t fd_get_u16(const uint8_t *p) {
    return FD_CAST(uint16_t, FD_CAST(unsigned, p[0]) | (FD_CAST(unsigned, p[1]) << 8));
}
static inline uint32_t fd_get_u32(const uint8_t *p) {
    return FD_CAST(uint32_t, p[0]) | (FD_CAST(uint32_t, p[1]) << 8) |
           (FD_CAST(uint32_t, p[2]) << 16) | (FD_CAST(uint32_t, p[3]) << 24);
}
static inline uint64_t fd_get_u64(const uint8_t *p) {
    return FD_CAST(uint64_t, fd_get_u32(p)) | (FD_CAST(uint64_t, fd_get_u32(p + 4)) << 32);
}
static inline double fd_get_f64(const uint8_t *p) {
    uint64_t bits = fd_get_u64(p);
    double d;
    memcpy(&d, &bits, sizeof d); /* IEEE-754 binary64 with the integer's byte order */
    return d;
}
static inline void fd_put_u16(uint8_t *p, uint16_t v) {
    p[0] = FD_CAST(uint8_t, v);
    p[1] = FD_CAST(uint8_t, v >> 8);
}
static inline void fd_put_u32(uint8_t *p, uint32_t v) {
    p[0] = FD_CAST(uint8_t, v);
    p[1] = FD_CAST(uint8_t, v >> 8);
    p[2] = FD_CAST(uint8_t, v >> 16);
    p[3] = FD_CAST(uint8_t, v >> 24);
}
static inline void fd_put_u64(uint8_t *p, uint64_t v) {
    fd_put_u32(p, FD_CAST(uint32_t, v));
    fd_put_u32(p + 4, FD_CAST(uint32_t, v >> 32));
}
static inline void fd_put_f64(uint8_t *p, double d) {
    uint64_t bits;
    memcpy(&bits, &d, sizeof bits);
    fd_put_u64(p, bits);
}
static inline int fd_is_finite(double d) {
    uint64_t bits;
    memcpy(&bits, &d, sizeof bits);
    return ((bits >> 52) & 0x7ffu) != 0x7ffu;
}
/* A count the decoder or encoder has already bounded by its FD_MAX_* (so at most 1024) as a
 * size_t. Without a cast where size_t is 64 bits wide (on LP64 it is the same type as uint64_t,
 * and C++'s -Wuseless-cast rejects a cast to the same type); with one where it is narrower. */
static inline size_t fd_size(uint64_t n) {
#if SIZE_MAX < UINT64_MAX
    return FD_CAST(size_t, n);
#else
    return n;
#endif
}
static inline void fd_get_f64s(const uint8_t *p, double *out, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i) out[i] = fd_get_f64(p + 8 * i);
}
static inline void fd_put_f64s(uint8_t *p, const double *v, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i) fd_put_f64(p + 8 * i, v[i]);
}

static inline fd_error fd_ok(void) {
    fd_error e;
    e.status = FD_OK;
    e.needed = 0;
    e.actual = 0;
    e.found_version = 0;
    e.field = FD_NULL;
    return e;
}
static inline fd_error fd_fail(fd_status s, size_t needed, size_t actual, const char *field) {
    fd_error e = fd_ok();
    e.status = s;
    e.needed = needed;
    e.actual = actual;
    e.field = field;
    return e;
}

/* Steps 1-2: size limit and version. min_len is the message type's shortest length. */
static inline fd_error fd_check_size_and_version(const uint8_t *buf, size_t len, size_t min_len) {
    uint16_t v;
    if (len > FD_MAX_MESSAGE_BYTES) return fd_fail(FD_ERR_TOO_LARGE, 0, len, FD_NULL);
    if (len < 2) return fd_fail(FD_ERR_LENGTH, min_len, len, FD_NULL);
    v = fd_get_u16(buf);
    if (v != FD_PROTOCOL_VERSION) {
        fd_error e = fd_fail(FD_ERR_UNKNOWN_VERSION, 0, len, FD_NULL);
        e.found_version = v;
        return e;
    }
    return fd_ok();
}

/* Step 3 helper: the expected total length versus the buffer. */
static inline fd_error fd_check_total(size_t expected, size_t len) {
    if (len < expected) return fd_fail(FD_ERR_LENGTH, expected, len, FD_NULL);
    if (len > expected) return fd_fail(FD_ERR_TRAILING_BYTES, expected, len, FD_NULL);
    return fd_ok();
}

/* A bounded cursor over count prefixes (step 3 of variable-length messages). */
typedef struct {
    size_t at;
    size_t len;
} fd_walker;

static inline fd_error fd_walk_skip(fd_walker *w, size_t n) {
    if (w->at + n > w->len) return fd_fail(FD_ERR_LENGTH, w->at + n, w->len, FD_NULL);
    w->at += n;
    return fd_ok();
}
static inline fd_error fd_walk_count(fd_walker *w, const uint8_t *buf, uint64_t max,
                                     const char *what, uint64_t *count) {
    if (w->at + 8 > w->len) return fd_fail(FD_ERR_LENGTH, w->at + 8, w->len, FD_NULL);
    *count = fd_get_u64(buf + w->at);
    if (*count > max) return fd_fail(FD_ERR_MALFORMED, 0, w->len, what);
    w->at += 8;
    return fd_ok();
}
static inline fd_error fd_walk_values(fd_walker *w, const uint8_t *buf, const char *what) {
    uint64_t n;
    fd_error e = fd_walk_count(w, buf, FD_MAX_EFFECTOR_VALUES, what, &n);
    if (e.status != FD_OK) return e;
    return fd_walk_skip(w, 8 * fd_size(n));
}

/* ------------------------------------------------------------------------------------------ */
/* Header.                                                                                     */

static inline void fd_decode_header_at(const uint8_t *p, fd_header *h) {
    h->protocol_version = fd_get_u16(p);
    h->spacecraft_id = fd_get_u32(p + 2);
    h->tick = fd_get_u64(p + 6);
    h->sim_time_ns = fd_get_u64(p + 14);
    h->seq = fd_get_u64(p + 22);
}
static inline void fd_encode_header_at(uint8_t *p, const fd_header *h) {
    fd_put_u16(p, h->protocol_version);
    fd_put_u32(p + 2, h->spacecraft_id);
    fd_put_u64(p + 6, h->tick);
    fd_put_u64(p + 14, h->sim_time_ns);
    fd_put_u64(p + 22, h->seq);
}

/* A header with the current protocol version. */
static inline fd_header fd_header_new(uint32_t spacecraft_id, uint64_t tick, uint64_t sim_time_ns,
                                      uint64_t seq) {
    fd_header h;
    h.protocol_version = FD_CAST(uint16_t, FD_PROTOCOL_VERSION);
    h.spacecraft_id = spacecraft_id;
    h.tick = tick;
    h.sim_time_ns = sim_time_ns;
    h.seq = seq;
    return h;
}

/* Only the header of any message (size, version and the first 30 bytes are checked). */
static inline fd_error fd_decode_header(const uint8_t *buf, size_t len, fd_header *out) {
    fd_error e = fd_check_size_and_version(buf, len, FD_HEADER_LEN);
    if (e.status != FD_OK) return e;
    if (len < FD_HEADER_LEN) return fd_fail(FD_ERR_LENGTH, FD_HEADER_LEN, len, FD_NULL);
    fd_decode_header_at(buf, out);
    return fd_ok();
}

/* ------------------------------------------------------------------------------------------ */
/* StateMsg.                                                                                   */

/* Encoded length of `m` (its n_effectors entries). */
static inline size_t fd_state_len(const fd_state_msg *m) {
    size_t n = FD_STATE_FIXED_LEN;
    uint64_t i;
    for (i = 0; i < m->n_effectors; ++i)
        n += FD_EFFECTOR_STATE_FIXED_LEN +
             8 * fd_size(m->effectors[i].n_states + m->effectors[i].n_outputs);
    return n;
}

static inline fd_error fd_decode_state(const uint8_t *buf, size_t len, fd_state_msg *out) {
    fd_walker w;
    uint64_t n, i;
    fd_error e = fd_check_size_and_version(buf, len, FD_STATE_FIXED_LEN);
    if (e.status != FD_OK) return e;
    w.at = FD_STATE_EFFECTOR_COUNT_OFFSET;
    w.len = len;
    if (len < FD_STATE_EFFECTOR_COUNT_OFFSET + 8)
        return fd_fail(FD_ERR_LENGTH, FD_STATE_FIXED_LEN, len, FD_NULL);
    e = fd_walk_count(&w, buf, FD_MAX_EFFECTORS, "effector count", &n);
    if (e.status != FD_OK) return e;
    for (i = 0; i < n; ++i) {
        if ((e = fd_walk_skip(&w, 6)).status != FD_OK) return e;
        if ((e = fd_walk_values(&w, buf, "effector states count")).status != FD_OK) return e;
        if ((e = fd_walk_values(&w, buf, "effector outputs count")).status != FD_OK) return e;
    }
    if ((e = fd_check_total(w.at, len)).status != FD_OK) return e;
    if (n > out->effectors_capacity) return fd_fail(FD_ERR_CAPACITY, fd_size(n), len, "effectors");
    fd_decode_header_at(buf, &out->header);
    fd_get_f64s(buf + 30, out->sigma_bn, 3);
    fd_get_f64s(buf + 54, out->q_bn, 4);
    fd_get_f64s(buf + 86, out->omega_bn_b_rad_s, 3);
    fd_get_f64s(buf + 110, out->omega_dot_bn_b_rad_s2, 3);
    fd_get_f64s(buf + 134, out->r_bn_n_m, 3);
    fd_get_f64s(buf + 158, out->v_bn_n_m_s, 3);
    fd_get_f64s(buf + 182, out->nongrav_accel_bn_n_m_s2, 3);
    out->orb_energy_j = fd_get_f64(buf + 206);
    out->rot_energy_j = fd_get_f64(buf + 214);
    fd_get_f64s(buf + 222, out->orb_ang_mom_n, 3);
    fd_get_f64s(buf + 246, out->rot_ang_mom_c_n, 3);
    fd_get_f64s(buf + 270, out->torque_b_nm, 3);
    fd_get_f64s(buf + 294, out->force_b_newton, 3);
    out->command_flags = buf[318];
    out->n_effectors = n;
    w.at = FD_STATE_FIXED_LEN;
    for (i = 0; i < n; ++i) {
        fd_effector_state *s = &out->effectors[i];
        s->kind = fd_get_u16(buf + w.at);
        s->flags = fd_get_u32(buf + w.at + 2);
        s->n_states = fd_get_u64(buf + w.at + 6);
        fd_get_f64s(buf + w.at + 14, s->states, fd_size(s->n_states));
        w.at += 14 + 8 * fd_size(s->n_states);
        s->n_outputs = fd_get_u64(buf + w.at);
        fd_get_f64s(buf + w.at + 8, s->outputs, fd_size(s->n_outputs));
        w.at += 8 + 8 * fd_size(s->n_outputs);
    }
    return fd_ok();
}

/* Encodes `m` into `buf` (capacity `cap`); returns the length, 0 if it does not fit or a
 * count exceeds its maximum. */
static inline size_t fd_encode_state(const fd_state_msg *m, uint8_t *buf, size_t cap) {
    size_t at, need;
    uint64_t i;
    if (m->n_effectors > FD_MAX_EFFECTORS) return 0;
    for (i = 0; i < m->n_effectors; ++i)
        if (m->effectors[i].n_states > FD_MAX_EFFECTOR_VALUES ||
            m->effectors[i].n_outputs > FD_MAX_EFFECTOR_VALUES)
            return 0;
    need = fd_state_len(m);
    if (need > cap) return 0;
    fd_encode_header_at(buf, &m->header);
    fd_put_f64s(buf + 30, m->sigma_bn, 3);
    fd_put_f64s(buf + 54, m->q_bn, 4);
    fd_put_f64s(buf + 86, m->omega_bn_b_rad_s, 3);
    fd_put_f64s(buf + 110, m->omega_dot_bn_b_rad_s2, 3);
    fd_put_f64s(buf + 134, m->r_bn_n_m, 3);
    fd_put_f64s(buf + 158, m->v_bn_n_m_s, 3);
    fd_put_f64s(buf + 182, m->nongrav_accel_bn_n_m_s2, 3);
    fd_put_f64(buf + 206, m->orb_energy_j);
    fd_put_f64(buf + 214, m->rot_energy_j);
    fd_put_f64s(buf + 222, m->orb_ang_mom_n, 3);
    fd_put_f64s(buf + 246, m->rot_ang_mom_c_n, 3);
    fd_put_f64s(buf + 270, m->torque_b_nm, 3);
    fd_put_f64s(buf + 294, m->force_b_newton, 3);
    buf[318] = m->command_flags;
    fd_put_u64(buf + 319, m->n_effectors);
    at = FD_STATE_FIXED_LEN;
    for (i = 0; i < m->n_effectors; ++i) {
        const fd_effector_state *s = &m->effectors[i];
        fd_put_u16(buf + at, s->kind);
        fd_put_u32(buf + at + 2, s->flags);
        fd_put_u64(buf + at + 6, s->n_states);
        fd_put_f64s(buf + at + 14, s->states, fd_size(s->n_states));
        at += 14 + 8 * fd_size(s->n_states);
        fd_put_u64(buf + at, s->n_outputs);
        fd_put_f64s(buf + at + 8, s->outputs, fd_size(s->n_outputs));
        at += 8 + 8 * fd_size(s->n_outputs);
    }
    return at;
}

/* ------------------------------------------------------------------------------------------ */
/* ImuMsg and StarTrackerMsg (fixed length).                                                   */

static inline fd_error fd_decode_imu(const uint8_t *buf, size_t len, fd_imu_msg *out) {
    fd_error e = fd_check_size_and_version(buf, len, FD_IMU_LEN);
    if (e.status != FD_OK) return e;
    if ((e = fd_check_total(FD_IMU_LEN, len)).status != FD_OK) return e;
    fd_decode_header_at(buf, &out->header);
    fd_get_f64s(buf + 30, out->omega_p_rad_s, 3);
    fd_get_f64s(buf + 54, out->accel_p_m_s2, 3);
    fd_get_f64s(buf + 78, out->dtheta_p_rad, 3);
    fd_get_f64s(buf + 102, out->dv_p_m_s, 3);
    out->saturation_flags = buf[126];
    return fd_ok();
}

static inline size_t fd_encode_imu(const fd_imu_msg *m, uint8_t *buf, size_t cap) {
    if (cap < FD_IMU_LEN) return 0;
    fd_encode_header_at(buf, &m->header);
    fd_put_f64s(buf + 30, m->omega_p_rad_s, 3);
    fd_put_f64s(buf + 54, m->accel_p_m_s2, 3);
    fd_put_f64s(buf + 78, m->dtheta_p_rad, 3);
    fd_put_f64s(buf + 102, m->dv_p_m_s, 3);
    buf[126] = m->saturation_flags;
    return FD_IMU_LEN;
}

static inline fd_error fd_decode_star_tracker(const uint8_t *buf, size_t len,
                                              fd_star_tracker_msg *out) {
    fd_error e = fd_check_size_and_version(buf, len, FD_STAR_TRACKER_LEN);
    if (e.status != FD_OK) return e;
    if ((e = fd_check_total(FD_STAR_TRACKER_LEN, len)).status != FD_OK) return e;
    if (buf[62] > 1) return fd_fail(FD_ERR_MALFORMED, 0, len, "valid is not a bool");
    fd_decode_header_at(buf, &out->header);
    fd_get_f64s(buf + 30, out->q_cn, 4);
    out->valid = buf[62];
    out->status_flags = buf[63];
    return fd_ok();
}

static inline size_t fd_encode_star_tracker(const fd_star_tracker_msg *m, uint8_t *buf,
                                            size_t cap) {
    if (cap < FD_STAR_TRACKER_LEN || m->valid > 1) return 0;
    fd_encode_header_at(buf, &m->header);
    fd_put_f64s(buf + 30, m->q_cn, 4);
    buf[62] = m->valid;
    buf[63] = m->status_flags;
    return FD_STAR_TRACKER_LEN;
}

static inline fd_error fd_decode_magnetometer(const uint8_t *buf, size_t len,
                                              fd_magnetometer_msg *out) {
    fd_error e = fd_check_size_and_version(buf, len, FD_MAGNETOMETER_LEN);
    if (e.status != FD_OK) return e;
    if ((e = fd_check_total(FD_MAGNETOMETER_LEN, len)).status != FD_OK) return e;
    fd_decode_header_at(buf, &out->header);
    fd_get_f64s(buf + 30, out->b_s_t, 3);
    out->saturation_flags = buf[54];
    return fd_ok();
}

static inline size_t fd_encode_magnetometer(const fd_magnetometer_msg *m, uint8_t *buf,
                                            size_t cap) {
    if (cap < FD_MAGNETOMETER_LEN) return 0;
    fd_encode_header_at(buf, &m->header);
    fd_put_f64s(buf + 30, m->b_s_t, 3);
    buf[54] = m->saturation_flags;
    return FD_MAGNETOMETER_LEN;
}

/* CssMsg and FssMsg (protocol 6, fixed length). */

static inline fd_error fd_decode_css(const uint8_t *buf, size_t len, fd_css_msg *out) {
    fd_error e = fd_check_size_and_version(buf, len, FD_CSS_LEN);
    if (e.status != FD_OK) return e;
    if ((e = fd_check_total(FD_CSS_LEN, len)).status != FD_OK) return e;
    if (buf[30] > FD_MAX_CSS_DETECTORS)
        return fd_fail(FD_ERR_MALFORMED, 0, len, "detector count exceeds maximum");
    fd_decode_header_at(buf, &out->header);
    out->detector_count = buf[30];
    fd_get_f64s(buf + 31, out->readings, FD_MAX_CSS_DETECTORS);
    return fd_ok();
}

static inline size_t fd_encode_css(const fd_css_msg *m, uint8_t *buf, size_t cap) {
    if (cap < FD_CSS_LEN || m->detector_count > FD_MAX_CSS_DETECTORS) return 0;
    fd_encode_header_at(buf, &m->header);
    buf[30] = m->detector_count;
    fd_put_f64s(buf + 31, m->readings, FD_MAX_CSS_DETECTORS);
    return FD_CSS_LEN;
}

static inline fd_error fd_decode_fss(const uint8_t *buf, size_t len, fd_fss_msg *out) {
    fd_error e = fd_check_size_and_version(buf, len, FD_FSS_LEN);
    if (e.status != FD_OK) return e;
    if ((e = fd_check_total(FD_FSS_LEN, len)).status != FD_OK) return e;
    fd_decode_header_at(buf, &out->header);
    fd_get_f64s(buf + 30, &out->alpha_rad, 1);
    fd_get_f64s(buf + 38, &out->beta_rad, 1);
    out->flags = buf[46];
    return fd_ok();
}

static inline size_t fd_encode_fss(const fd_fss_msg *m, uint8_t *buf, size_t cap) {
    if (cap < FD_FSS_LEN) return 0;
    fd_encode_header_at(buf, &m->header);
    fd_put_f64s(buf + 30, &m->alpha_rad, 1);
    fd_put_f64s(buf + 38, &m->beta_rad, 1);
    buf[46] = m->flags;
    return FD_FSS_LEN;
}

/* ------------------------------------------------------------------------------------------ */
/* CommandMsg.                                                                                 */

static const char *const fd_torque_fields[3] = {"kind.torque_b_nm[0]", "kind.torque_b_nm[1]",
                                                "kind.torque_b_nm[2]"};
static const char *const fd_force_fields[3] = {
    "kind.force_b_newton[0]", "kind.force_b_newton[1]", "kind.force_b_newton[2]"};

/* Encoded length of `m`, 0 for an unknown kind. */
static inline size_t fd_command_len(const fd_command_msg *m) {
    size_t n;
    uint64_t i;
    switch (m->kind) {
    case FD_COMMAND_WRENCH: return FD_COMMAND_WRENCH_LEN;
    case FD_COMMAND_NO_COMMAND: return FD_COMMAND_NO_COMMAND_LEN;
    case FD_COMMAND_ACTUATORS:
        n = FD_COMMAND_ACTUATORS_FIXED_LEN;
        for (i = 0; i < m->n_inputs; ++i)
            n += FD_EFFECTOR_INPUT_FIXED_LEN + 8 * fd_size(m->inputs[i].n_values);
        return n;
    default: return 0;
    }
}

/* Step 5 (also usable before sending): every torque, force and input value finite. */
static inline fd_error fd_validate_command(const fd_command_msg *m, size_t len) {
    uint64_t i, j;
    int k;
    if (m->kind == FD_COMMAND_NO_COMMAND) return fd_ok();
    for (k = 0; k < 3; ++k)
        if (!fd_is_finite(m->torque_b_nm[k]))
            return fd_fail(FD_ERR_NON_FINITE, 0, len, fd_torque_fields[k]);
    for (k = 0; k < 3; ++k)
        if (!fd_is_finite(m->force_b_newton[k]))
            return fd_fail(FD_ERR_NON_FINITE, 0, len, fd_force_fields[k]);
    if (m->kind == FD_COMMAND_ACTUATORS)
        for (i = 0; i < m->n_inputs; ++i)
            for (j = 0; j < m->inputs[i].n_values; ++j)
                if (!fd_is_finite(m->inputs[i].values[j]))
                    return fd_fail(FD_ERR_NON_FINITE, 0, len, "kind.inputs[].values[]");
    return fd_ok();
}

static inline fd_error fd_decode_command(const uint8_t *buf, size_t len, fd_command_msg *out) {
    uint32_t tag;
    size_t expected;
    uint64_t n = 0, i;
    fd_error e = fd_check_size_and_version(buf, len, FD_COMMAND_NO_COMMAND_LEN);
    if (e.status != FD_OK) return e;
    if (len < FD_COMMAND_KIND_OFFSET + 4)
        return fd_fail(FD_ERR_LENGTH, FD_COMMAND_NO_COMMAND_LEN, len, FD_NULL);
    tag = fd_get_u32(buf + FD_COMMAND_KIND_OFFSET);
    if (tag == FD_COMMAND_WRENCH) {
        expected = FD_COMMAND_WRENCH_LEN;
    } else if (tag == FD_COMMAND_NO_COMMAND) {
        expected = FD_COMMAND_NO_COMMAND_LEN;
    } else if (tag == FD_COMMAND_ACTUATORS) {
        fd_walker w;
        w.at = FD_COMMAND_ACTUATORS_FIXED_LEN - 8;
        w.len = len;
        e = fd_walk_count(&w, buf, FD_MAX_EFFECTORS, "effector input count", &n);
        if (e.status != FD_OK) return e;
        for (i = 0; i < n; ++i) {
            if ((e = fd_walk_skip(&w, 4)).status != FD_OK) return e;
            if ((e = fd_walk_values(&w, buf, "effector input values count")).status != FD_OK)
                return e;
        }
        expected = w.at;
    } else {
        return fd_fail(FD_ERR_MALFORMED, 0, len, "unknown command kind tag");
    }
    if ((e = fd_check_total(expected, len)).status != FD_OK) return e;
    fd_decode_header_at(buf, &out->header);
    out->sender_id = fd_get_u32(buf + 30);
    out->kind = tag;
    out->n_inputs = 0;
    memset(out->torque_b_nm, 0, sizeof out->torque_b_nm);
    memset(out->force_b_newton, 0, sizeof out->force_b_newton);
    if (tag == FD_COMMAND_NO_COMMAND) return fd_ok();
    fd_get_f64s(buf + 38, out->torque_b_nm, 3);
    fd_get_f64s(buf + 62, out->force_b_newton, 3);
    /* Rule 5 in order: torque and force (no inputs stored yet), then the input values, read
     * from the buffer so the order holds even when they will not fit the caller's array. */
    if ((e = fd_validate_command(out, len)).status != FD_OK) return e;
    if (tag == FD_COMMAND_ACTUATORS) {
        size_t at = FD_COMMAND_ACTUATORS_FIXED_LEN;
        for (i = 0; i < n; ++i) {
            uint64_t v = fd_get_u64(buf + at + 4), j;
            for (j = 0; j < v; ++j)
                if (!fd_is_finite(fd_get_f64(buf + at + 12 + 8 * j)))
                    return fd_fail(FD_ERR_NON_FINITE, 0, len, "kind.inputs[].values[]");
            at += 12 + 8 * fd_size(v);
        }
        if (n > out->inputs_capacity) return fd_fail(FD_ERR_CAPACITY, fd_size(n), len, "inputs");
        at = FD_COMMAND_ACTUATORS_FIXED_LEN;
        for (i = 0; i < n; ++i) {
            fd_effector_input *in = &out->inputs[i];
            in->effector_index = fd_get_u32(buf + at);
            in->n_values = fd_get_u64(buf + at + 4);
            fd_get_f64s(buf + at + 12, in->values, fd_size(in->n_values));
            at += 12 + 8 * fd_size(in->n_values);
        }
        out->n_inputs = n;
    }
    return fd_ok();
}

/* Encodes `m` (any kind); returns the length, 0 for an unknown kind, a count above its
 * maximum, or too small a buffer. It does not check finiteness: call fd_validate_command. */
static inline size_t fd_encode_command(const fd_command_msg *m, uint8_t *buf, size_t cap) {
    size_t need, at;
    uint64_t i;
    if (m->kind == FD_COMMAND_ACTUATORS) {
        if (m->n_inputs > FD_MAX_EFFECTORS) return 0;
        for (i = 0; i < m->n_inputs; ++i)
            if (m->inputs[i].n_values > FD_MAX_EFFECTOR_VALUES) return 0;
    }
    need = fd_command_len(m);
    if (need == 0 || need > cap) return 0;
    fd_encode_header_at(buf, &m->header);
    fd_put_u32(buf + 30, m->sender_id);
    fd_put_u32(buf + 34, m->kind);
    if (m->kind == FD_COMMAND_NO_COMMAND) return need;
    fd_put_f64s(buf + 38, m->torque_b_nm, 3);
    fd_put_f64s(buf + 62, m->force_b_newton, 3);
    if (m->kind == FD_COMMAND_WRENCH) return need;
    fd_put_u64(buf + 86, m->n_inputs);
    at = FD_COMMAND_ACTUATORS_FIXED_LEN;
    for (i = 0; i < m->n_inputs; ++i) {
        fd_put_u32(buf + at, m->inputs[i].effector_index);
        fd_put_u64(buf + at + 4, m->inputs[i].n_values);
        fd_put_f64s(buf + at + 12, m->inputs[i].values, fd_size(m->inputs[i].n_values));
        at += 12 + 8 * fd_size(m->inputs[i].n_values);
    }
    return at;
}

/* ------------------------------------------------------------------------------------------ */
/* StatusMsg.                                                                                  */

static inline fd_error fd_decode_status(const uint8_t *buf, size_t len, fd_status_msg *out) {
    fd_error e = fd_check_size_and_version(buf, len, FD_STATUS_LEN);
    if (e.status != FD_OK) return e;
    if ((e = fd_check_total(FD_STATUS_LEN, len)).status != FD_OK) return e;
    /* Step 4 in wire order: mode tag, run_state tag, command_stale bool, stale_policy tag. */
    if (fd_get_u32(buf + 30) > FD_MODE_BATCH) return fd_fail(FD_ERR_MALFORMED, 0, len, "mode tag");
    if (fd_get_u32(buf + 34) > FD_RUN_STATE_PAUSED)
        return fd_fail(FD_ERR_MALFORMED, 0, len, "run_state tag");
    if (buf[94] > 1) return fd_fail(FD_ERR_MALFORMED, 0, len, "command_stale is not a bool");
    if (fd_get_u32(buf + 95) > FD_STALE_POLICY_ZERO)
        return fd_fail(FD_ERR_MALFORMED, 0, len, "stale_policy tag");
    fd_decode_header_at(buf, &out->header);
    out->mode = fd_get_u32(buf + 30);
    out->run_state = fd_get_u32(buf + 34);
    out->lateness_p50_ns = fd_get_u64(buf + 38);
    out->lateness_p99_ns = fd_get_u64(buf + 46);
    out->lateness_max_ns = fd_get_u64(buf + 54);
    out->overrun_count = fd_get_u64(buf + 62);
    out->frames_skipped = fd_get_u64(buf + 70);
    out->last_command_tick = fd_get_u64(buf + 78);
    out->command_age_ns = fd_get_u64(buf + 86);
    out->command_stale = buf[94];
    out->stale_policy = fd_get_u32(buf + 95);
    out->rejected_malformed = fd_get_u64(buf + 99);
    out->rejected_bad_version = fd_get_u64(buf + 107);
    out->rejected_non_finite = fd_get_u64(buf + 115);
    out->rejected_wrong_spacecraft = fd_get_u64(buf + 123);
    out->rejected_stale_tick = fd_get_u64(buf + 131);
    out->rejected_unknown_sender = fd_get_u64(buf + 139);
    out->rejected_bad_effector_input = fd_get_u64(buf + 147);
    out->rejected_wrong_identity = fd_get_u64(buf + 155);
    out->rejected_operator_refused = fd_get_u64(buf + 163);
    out->rejected_fault_refused = fd_get_u64(buf + 171);
    out->commands_dropped = fd_get_u64(buf + 179);
    out->wall_time_unix_ns = fd_get_u64(buf + 187);
    out->faults_active = fd_get_u64(buf + 195);
    out->faults_active_bits[0] = fd_get_u64(buf + 203);
    out->faults_active_bits[1] = fd_get_u64(buf + 211);
    out->faults_active_bits[2] = fd_get_u64(buf + 219);
    out->faults_active_bits[3] = fd_get_u64(buf + 227);
    return fd_ok();
}

static inline size_t fd_encode_status(const fd_status_msg *m, uint8_t *buf, size_t cap) {
    if (cap < FD_STATUS_LEN || m->command_stale > 1) return 0;
    fd_encode_header_at(buf, &m->header);
    fd_put_u32(buf + 30, m->mode);
    fd_put_u32(buf + 34, m->run_state);
    fd_put_u64(buf + 38, m->lateness_p50_ns);
    fd_put_u64(buf + 46, m->lateness_p99_ns);
    fd_put_u64(buf + 54, m->lateness_max_ns);
    fd_put_u64(buf + 62, m->overrun_count);
    fd_put_u64(buf + 70, m->frames_skipped);
    fd_put_u64(buf + 78, m->last_command_tick);
    fd_put_u64(buf + 86, m->command_age_ns);
    buf[94] = m->command_stale;
    fd_put_u32(buf + 95, m->stale_policy);
    fd_put_u64(buf + 99, m->rejected_malformed);
    fd_put_u64(buf + 107, m->rejected_bad_version);
    fd_put_u64(buf + 115, m->rejected_non_finite);
    fd_put_u64(buf + 123, m->rejected_wrong_spacecraft);
    fd_put_u64(buf + 131, m->rejected_stale_tick);
    fd_put_u64(buf + 139, m->rejected_unknown_sender);
    fd_put_u64(buf + 147, m->rejected_bad_effector_input);
    fd_put_u64(buf + 155, m->rejected_wrong_identity);
    fd_put_u64(buf + 163, m->rejected_operator_refused);
    fd_put_u64(buf + 171, m->rejected_fault_refused);
    fd_put_u64(buf + 179, m->commands_dropped);
    fd_put_u64(buf + 187, m->wall_time_unix_ns);
    fd_put_u64(buf + 195, m->faults_active);
    fd_put_u64(buf + 203, m->faults_active_bits[0]);
    fd_put_u64(buf + 211, m->faults_active_bits[1]);
    fd_put_u64(buf + 219, m->faults_active_bits[2]);
    fd_put_u64(buf + 227, m->faults_active_bits[3]);
    return FD_STATUS_LEN;
}

/* ------------------------------------------------------------------------------------------ */
/* TimeMsg (protocol 5).                                                                       */

static inline fd_error fd_decode_time(const uint8_t *buf, size_t len, fd_time_msg *out) {
    fd_error e = fd_check_size_and_version(buf, len, FD_TIME_LEN);
    if (e.status != FD_OK) return e;
    if ((e = fd_check_total(FD_TIME_LEN, len)).status != FD_OK) return e;
    if (fd_get_u32(buf + 30) > FD_RUN_STATE_PAUSED)
        return fd_fail(FD_ERR_MALFORMED, 0, len, "run_state tag");
    if (fd_get_u32(buf + 34) > FD_MODE_BATCH) return fd_fail(FD_ERR_MALFORMED, 0, len, "mode tag");
    fd_decode_header_at(buf, &out->header);
    out->run_state = fd_get_u32(buf + 30);
    out->mode = fd_get_u32(buf + 34);
    out->flags = buf[38];
    out->frame_ns = fd_get_u64(buf + 39);
    out->speed = fd_get_f64(buf + 47);
    out->tai_ns_1958 = fd_get_u64(buf + 55);
    out->utc_year = fd_get_u16(buf + 63);
    out->utc_month = buf[65];
    out->utc_day = buf[66];
    out->utc_hour = buf[67];
    out->utc_minute = buf[68];
    out->utc_second = buf[69];
    out->utc_nanosecond = fd_get_u32(buf + 70);
    {
        uint32_t u = fd_get_u32(buf + 74); /* two's complement, read without a signed overflow */
        out->tai_minus_utc_s = u <= 0x7FFFFFFFu ? FD_CAST(int32_t, u)
                                                : -FD_CAST(int32_t, ~u) - 1;
    }
    out->gps_week = fd_get_u32(buf + 78);
    out->gps_ns_of_week = fd_get_u64(buf + 82);
    out->met_ns = fd_get_u64(buf + 90);
    memcpy(out->cuc_tai, buf + FD_TIME_CUC_OFFSET, 8);
    out->tone_met.seconds = fd_get_u32(buf + 106);
    out->tone_met.subseconds = fd_get_u32(buf + 110);
    out->tone_tai.seconds = fd_get_u32(buf + 114);
    out->tone_tai.subseconds = fd_get_u32(buf + 118);
    return fd_ok();
}

static inline size_t fd_encode_time(const fd_time_msg *m, uint8_t *buf, size_t cap) {
    if (cap < FD_TIME_LEN) return 0;
    fd_encode_header_at(buf, &m->header);
    fd_put_u32(buf + 30, m->run_state);
    fd_put_u32(buf + 34, m->mode);
    buf[38] = m->flags;
    fd_put_u64(buf + 39, m->frame_ns);
    fd_put_f64(buf + 47, m->speed);
    fd_put_u64(buf + 55, m->tai_ns_1958);
    fd_put_u16(buf + 63, m->utc_year);
    buf[65] = m->utc_month;
    buf[66] = m->utc_day;
    buf[67] = m->utc_hour;
    buf[68] = m->utc_minute;
    buf[69] = m->utc_second;
    fd_put_u32(buf + 70, m->utc_nanosecond);
    fd_put_u32(buf + 74, FD_CAST(uint32_t, m->tai_minus_utc_s));
    fd_put_u32(buf + 78, m->gps_week);
    fd_put_u64(buf + 82, m->gps_ns_of_week);
    fd_put_u64(buf + 90, m->met_ns);
    memcpy(buf + FD_TIME_CUC_OFFSET, m->cuc_tai, 8);
    fd_put_u32(buf + 106, m->tone_met.seconds);
    fd_put_u32(buf + 110, m->tone_met.subseconds);
    fd_put_u32(buf + 114, m->tone_tai.seconds);
    fd_put_u32(buf + 118, m->tone_tai.subseconds);
    return FD_TIME_LEN;
}

/* ------------------------------------------------------------------------------------------ */
/* OperatorMsg (protocol 6).                                                                   */

static inline fd_error fd_decode_operator(const uint8_t *buf, size_t len, fd_operator_msg *out) {
    fd_error e = fd_check_size_and_version(buf, len, FD_OPERATOR_LEN);
    if (e.status != FD_OK) return e;
    if ((e = fd_check_total(FD_OPERATOR_LEN, len)).status != FD_OK) return e;
    if (fd_get_u32(buf + 30) > FD_OPERATOR_RUN_TICKS)
        return fd_fail(FD_ERR_MALFORMED, 0, len, "action tag");
    fd_decode_header_at(buf, &out->header);
    out->action = fd_get_u32(buf + 30);
    out->ticks = fd_get_u64(buf + 34);
    return fd_ok();
}

static inline size_t fd_encode_operator(const fd_operator_msg *m, uint8_t *buf, size_t cap) {
    if (cap < FD_OPERATOR_LEN) return 0;
    fd_encode_header_at(buf, &m->header);
    fd_put_u32(buf + 30, m->action);
    fd_put_u64(buf + 34, m->ticks);
    return FD_OPERATOR_LEN;
}

/* EnvironmentMsg (protocol 6).                                                                */

static inline fd_error fd_decode_environment(const uint8_t *buf, size_t len,
                                             fd_environment_msg *out) {
    fd_error e = fd_check_size_and_version(buf, len, FD_ENVIRONMENT_LEN);
    fd_source_wrench *src[4];
    size_t i;
    if (e.status != FD_OK) return e;
    if ((e = fd_check_total(FD_ENVIRONMENT_LEN, len)).status != FD_OK) return e;
    fd_decode_header_at(buf, &out->header);
    out->tai_ns_1958 = fd_get_u64(buf + 30);
    out->flags = buf[38];
    out->eclipse = buf[39];
    fd_get_f64s(buf + 40, out->b_n_t, 3);
    fd_get_f64s(buf + 64, out->b_b_t, 3);
    fd_get_f64s(buf + 88, out->sun_n, 3);
    fd_get_f64s(buf + 112, out->sun_b, 3);
    fd_get_f64s(buf + 136, out->moon_n, 3);
    out->shadow_factor = fd_get_f64(buf + 160);
    out->density_kg_m3 = fd_get_f64(buf + 168);
    src[0] = &out->gravity_gradient;
    src[1] = &out->drag;
    src[2] = &out->solar_pressure;
    src[3] = &out->residual_dipole;
    for (i = 0; i < 4; ++i) {
        fd_get_f64s(buf + 176 + 48 * i, src[i]->torque_b_nm, 3);
        fd_get_f64s(buf + 200 + 48 * i, src[i]->force_b_newton, 3);
    }
    return fd_ok();
}

static inline size_t fd_encode_environment(const fd_environment_msg *m, uint8_t *buf,
                                           size_t cap) {
    const fd_source_wrench *src[4];
    size_t i;
    if (cap < FD_ENVIRONMENT_LEN) return 0;
    fd_encode_header_at(buf, &m->header);
    fd_put_u64(buf + 30, m->tai_ns_1958);
    buf[38] = m->flags;
    buf[39] = m->eclipse;
    fd_put_f64s(buf + 40, m->b_n_t, 3);
    fd_put_f64s(buf + 64, m->b_b_t, 3);
    fd_put_f64s(buf + 88, m->sun_n, 3);
    fd_put_f64s(buf + 112, m->sun_b, 3);
    fd_put_f64s(buf + 136, m->moon_n, 3);
    fd_put_f64(buf + 160, m->shadow_factor);
    fd_put_f64(buf + 168, m->density_kg_m3);
    src[0] = &m->gravity_gradient;
    src[1] = &m->drag;
    src[2] = &m->solar_pressure;
    src[3] = &m->residual_dipole;
    for (i = 0; i < 4; ++i) {
        fd_put_f64s(buf + 176 + 48 * i, src[i]->torque_b_nm, 3);
        fd_put_f64s(buf + 200 + 48 * i, src[i]->force_b_newton, 3);
    }
    return FD_ENVIRONMENT_LEN;
}

/* GpsMsg (protocol 7, fixed length).                                                          */

static inline fd_error fd_decode_gps(const uint8_t *buf, size_t len, fd_gps_msg *out) {
    fd_error e = fd_check_size_and_version(buf, len, FD_GPS_LEN);
    if (e.status != FD_OK) return e;
    if ((e = fd_check_total(FD_GPS_LEN, len)).status != FD_OK) return e;
    fd_decode_header_at(buf, &out->header);
    out->valid_sim_time_ns = fd_get_u64(buf + 30);
    out->gps_week = fd_get_u32(buf + 38);
    out->gps_seconds_of_week = fd_get_f64(buf + 42);
    fd_get_f64s(buf + 50, out->r_be_e_m, 3);
    fd_get_f64s(buf + 74, out->v_be_e_m_s, 3);
    fd_get_f64s(buf + 98, out->r_bn_n_m, 3);
    fd_get_f64s(buf + 122, out->v_bn_n_m_s, 3);
    out->flags = buf[146];
    return fd_ok();
}

static inline size_t fd_encode_gps(const fd_gps_msg *m, uint8_t *buf, size_t cap) {
    if (cap < FD_GPS_LEN) return 0;
    fd_encode_header_at(buf, &m->header);
    fd_put_u64(buf + 30, m->valid_sim_time_ns);
    fd_put_u32(buf + 38, m->gps_week);
    fd_put_f64(buf + 42, m->gps_seconds_of_week);
    fd_put_f64s(buf + 50, m->r_be_e_m, 3);
    fd_put_f64s(buf + 74, m->v_be_e_m_s, 3);
    fd_put_f64s(buf + 98, m->r_bn_n_m, 3);
    fd_put_f64s(buf + 122, m->v_bn_n_m_s, 3);
    buf[146] = m->flags;
    return FD_GPS_LEN;
}

/* FaultEventMsg and FaultCommandMsg (protocol 8, fixed length).                             */

/* The text rule (README "Decoder rules", step 4): a text field ends at its first NUL byte and
 * every byte after it is NUL. 1 when `p[0..n)` follows it. */
static inline int fd_text_padded(const uint8_t *p, size_t n) {
    size_t i = 0;
    while (i < n && p[i] != 0u) ++i;
    for (; i < n; ++i)
        if (p[i] != 0u) return 0;
    return 1;
}

static inline fd_error fd_decode_fault_event(const uint8_t *buf, size_t len,
                                             fd_fault_event_msg *out) {
    fd_error e = fd_check_size_and_version(buf, len, FD_FAULT_EVENT_LEN);
    size_t i;
    if (e.status != FD_OK) return e;
    if ((e = fd_check_total(FD_FAULT_EVENT_LEN, len)).status != FD_OK) return e;
    /* Step 4 in wire order: the source tag, the active bool. */
    if (fd_get_u32(buf + 34) > FD_FAULT_SOURCE_RANDOM)
        return fd_fail(FD_ERR_MALFORMED, 0, len, "source tag");
    if (buf[42] > 1) return fd_fail(FD_ERR_MALFORMED, 0, len, "active is not a bool");
    if (!fd_text_padded(buf + 71, FD_FAULT_TARGET_LEN))
        return fd_fail(FD_ERR_MALFORMED, 0, len, "target: a byte other than NUL after its NUL");
    fd_decode_header_at(buf, &out->header);
    out->fault_index = fd_get_u32(buf + 30);
    out->source = fd_get_u32(buf + 34);
    out->mode = fd_get_u32(buf + 38);
    out->active = buf[42];
    out->edge_ns = fd_get_u64(buf + 43);
    out->axes = fd_get_u32(buf + 51);
    fd_get_f64s(buf + 55, out->params, 2);
    for (i = 0; i < FD_FAULT_TARGET_LEN; ++i) out->target[i] = buf[71 + i];
    return fd_ok();
}

static inline size_t fd_encode_fault_event(const fd_fault_event_msg *m, uint8_t *buf,
                                           size_t cap) {
    size_t i;
    if (cap < FD_FAULT_EVENT_LEN || m->active > 1) return 0;
    fd_encode_header_at(buf, &m->header);
    fd_put_u32(buf + 30, m->fault_index);
    fd_put_u32(buf + 34, m->source);
    fd_put_u32(buf + 38, m->mode);
    buf[42] = m->active;
    fd_put_u64(buf + 43, m->edge_ns);
    fd_put_u32(buf + 51, m->axes);
    fd_put_f64s(buf + 55, m->params, 2);
    for (i = 0; i < FD_FAULT_TARGET_LEN; ++i) buf[71 + i] = m->target[i];
    return FD_FAULT_EVENT_LEN;
}

static inline fd_error fd_decode_fault_command(const uint8_t *buf, size_t len,
                                               fd_fault_command_msg *out) {
    fd_error e = fd_check_size_and_version(buf, len, FD_FAULT_COMMAND_LEN);
    size_t i;
    if (e.status != FD_OK) return e;
    if ((e = fd_check_total(FD_FAULT_COMMAND_LEN, len)).status != FD_OK) return e;
    if (fd_get_u32(buf + 30) > FD_FAULT_CLEAR)
        return fd_fail(FD_ERR_MALFORMED, 0, len, "action tag");
    if (!fd_text_padded(buf + 86, FD_FAULT_TARGET_LEN))
        return fd_fail(FD_ERR_MALFORMED, 0, len, "target: a byte other than NUL after its NUL");
    /* Step 5: the parameters finite. */
    if (!fd_is_finite(fd_get_f64(buf + 50))) return fd_fail(FD_ERR_NON_FINITE, 0, len, "params[0]");
    if (!fd_is_finite(fd_get_f64(buf + 58))) return fd_fail(FD_ERR_NON_FINITE, 0, len, "params[1]");
    fd_decode_header_at(buf, &out->header);
    out->action = fd_get_u32(buf + 30);
    out->at_tick = fd_get_u64(buf + 34);
    out->fault_index = fd_get_u32(buf + 42);
    out->mode = fd_get_u32(buf + 46);
    fd_get_f64s(buf + 50, out->params, 2);
    out->axes = fd_get_u32(buf + 66);
    out->duration_ns = fd_get_u64(buf + 70);
    out->seed = fd_get_u64(buf + 78);
    for (i = 0; i < FD_FAULT_TARGET_LEN; ++i) out->target[i] = buf[86 + i];
    return fd_ok();
}

static inline size_t fd_encode_fault_command(const fd_fault_command_msg *m, uint8_t *buf,
                                             size_t cap) {
    size_t i;
    if (cap < FD_FAULT_COMMAND_LEN) return 0;
    fd_encode_header_at(buf, &m->header);
    fd_put_u32(buf + 30, m->action);
    fd_put_u64(buf + 34, m->at_tick);
    fd_put_u32(buf + 42, m->fault_index);
    fd_put_u32(buf + 46, m->mode);
    fd_put_f64s(buf + 50, m->params, 2);
    fd_put_u32(buf + 66, m->axes);
    fd_put_u64(buf + 70, m->duration_ns);
    fd_put_u64(buf + 78, m->seed);
    for (i = 0; i < FD_FAULT_TARGET_LEN; ++i) buf[86 + i] = m->target[i];
    return FD_FAULT_COMMAND_LEN;
}

/* RelativeStateMsg (protocol 9, fixed length).                                               */

static inline fd_error fd_decode_relative_state(const uint8_t *buf, size_t len,
                                                fd_relative_state_msg *out) {
    fd_error e = fd_check_size_and_version(buf, len, FD_RELATIVE_STATE_LEN);
    if (e.status != FD_OK) return e;
    if ((e = fd_check_total(FD_RELATIVE_STATE_LEN, len)).status != FD_OK) return e;
    fd_decode_header_at(buf, &out->header);
    out->chief_spacecraft_id = fd_get_u32(buf + 30);
    out->deputy_spacecraft_id = fd_get_u32(buf + 34);
    fd_get_f64s(buf + 38, out->r_dc_h_m, 3);
    fd_get_f64s(buf + 62, out->v_dc_h_m_s, 3);
    out->range_m = fd_get_f64(buf + 86);
    out->range_rate_m_s = fd_get_f64(buf + 94);
    return fd_ok();
}

static inline size_t fd_encode_relative_state(const fd_relative_state_msg *m, uint8_t *buf,
                                              size_t cap) {
    if (cap < FD_RELATIVE_STATE_LEN) return 0;
    fd_encode_header_at(buf, &m->header);
    fd_put_u32(buf + 30, m->chief_spacecraft_id);
    fd_put_u32(buf + 34, m->deputy_spacecraft_id);
    fd_put_f64s(buf + 38, m->r_dc_h_m, 3);
    fd_put_f64s(buf + 62, m->v_dc_h_m_s, 3);
    fd_put_f64(buf + 86, m->range_m);
    fd_put_f64(buf + 94, m->range_rate_m_s);
    return FD_RELATIVE_STATE_LEN;
}

/* ------------------------------------------------------------------------------------------ */
/* Key expressions (proto/README.md, "Topics").                                                */

/* Whether `id` is a valid key chunk: 1-64 characters from [A-Za-z0-9_-]. */
static inline int fd_valid_id(const char *id) {
    size_t n = 0;
    for (; id[n] != '\0'; ++n) {
        char c = id[n];
        int ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                 c == '_' || c == '-';
        if (!ok || n >= 64) return 0;
    }
    return n > 0;
}

/* Writes "flexdyn/<sc>/<suffix>[/<name>]" into out (capacity cap, NUL-terminated); returns the
 * length, or 0 if an id is invalid or it does not fit. name may be null. */
static inline size_t fd_key(char *out, size_t cap, const char *sc, const char *suffix,
                            const char *name) {
    size_t n = 0, k;
    const char *parts[6];
    size_t count = 0;
    if (!fd_valid_id(sc) || (name != FD_NULL && !fd_valid_id(name))) return 0;
    parts[count++] = "flexdyn/";
    parts[count++] = sc;
    parts[count++] = "/";
    parts[count++] = suffix;
    if (name != FD_NULL) {
        parts[count++] = "/";
        parts[count++] = name;
    }
    for (k = 0; k < count; ++k) {
        size_t l = strlen(parts[k]);
        if (n + l + 1 > cap) return 0;
        memcpy(out + n, parts[k], l);
        n += l;
    }
    out[n] = '\0';
    return n;
}

static inline size_t fd_state_key(char *out, size_t cap, const char *sc) {
    return fd_key(out, cap, sc, "tlm/state", FD_NULL);
}
static inline size_t fd_time_key(char *out, size_t cap, const char *sc) {
    return fd_key(out, cap, sc, "tlm/time", FD_NULL);
}
static inline size_t fd_environment_key(char *out, size_t cap, const char *sc) {
    return fd_key(out, cap, sc, "tlm/env", FD_NULL);
}
static inline size_t fd_imu_key(char *out, size_t cap, const char *sc, const char *name) {
    return fd_key(out, cap, sc, "tlm/imu", name);
}
static inline size_t fd_star_tracker_key(char *out, size_t cap, const char *sc, const char *name) {
    return fd_key(out, cap, sc, "tlm/st", name);
}
static inline size_t fd_magnetometer_key(char *out, size_t cap, const char *sc,
                                         const char *name) {
    return fd_key(out, cap, sc, "tlm/mag", name);
}
static inline size_t fd_css_key(char *out, size_t cap, const char *sc, const char *name) {
    return fd_key(out, cap, sc, "tlm/css", name);
}
static inline size_t fd_fss_key(char *out, size_t cap, const char *sc, const char *name) {
    return fd_key(out, cap, sc, "tlm/fss", name);
}
static inline size_t fd_gps_key(char *out, size_t cap, const char *sc, const char *name) {
    return fd_key(out, cap, sc, "tlm/gps", name);
}
static inline size_t fd_status_key(char *out, size_t cap, const char *sc) {
    return fd_key(out, cap, sc, "status", FD_NULL);
}
/* flexdyn/<sc>/operator: operator commands (since protocol 6). */
static inline size_t fd_operator_key(char *out, size_t cap, const char *sc) {
    return fd_key(out, cap, sc, "operator", FD_NULL);
}
/* flexdyn/<sc>/fault: live fault commands (since protocol 8). */
static inline size_t fd_fault_key(char *out, size_t cap, const char *sc) {
    return fd_key(out, cap, sc, "fault", FD_NULL);
}
/* flexdyn/<sc>/tlm/fault: fault activations and clearances (since protocol 8). */
static inline size_t fd_fault_event_key(char *out, size_t cap, const char *sc) {
    return fd_key(out, cap, sc, "tlm/fault", FD_NULL);
}
/* flexdyn/<deputy>/tlm/rel/<chief>: a fleet deputy's state relative to its chief (since
 * protocol 9). */
static inline size_t fd_relative_state_key(char *out, size_t cap, const char *deputy,
                                           const char *chief) {
    return fd_key(out, cap, deputy, "tlm/rel", chief);
}
/* Writes the decimal form of v (no leading zero) into digits[11]; returns its first char. */
static inline const char *fd_decimal_u32(char digits[11], uint32_t v) {
    int i = 10;
    digits[10] = '\0';
    do {
        digits[--i] = FD_CAST(char, '0' + v % 10u);
        v /= 10u;
    } while (v != 0 && i > 0);
    return digits + i;
}
/* The command key of participant sender_id, flexdyn/<sc>/cmd/<sender_id> (protocol 4: one key
 * per sender, so the server's Zenoh access-control list can reserve it for one subject). */
static inline size_t fd_command_key(char *out, size_t cap, const char *sc, uint32_t sender_id) {
    char digits[11];
    return fd_key(out, cap, sc, "cmd", fd_decimal_u32(digits, sender_id));
}
/* The lockstep participant's liveliness token key, flexdyn/<sc>/participant/<sender_id>. */
static inline size_t fd_participant_key(char *out, size_t cap, const char *sc, uint32_t sender_id) {
    char digits[11];
    return fd_key(out, cap, sc, "participant", fd_decimal_u32(digits, sender_id));
}

#undef FD_CAST
#undef FD_NULL

#endif /* FLEXDYN_PROTO_H */
