/*
 * layout.c - the library hands out the structs of flexdyn_proto.h exactly as the header lays
 * them out. Each golden message (proto/golden, hand-derived, every field distinct) is decoded
 * twice: by the header's own fd_decode_* and by the library (the Rust codec, then its
 * conversion into the C struct). Every field must be equal bit for bit, and every struct the
 * same size on both sides. A field the Rust mirror puts at another offset or gives another
 * type shows up as a difference here.
 *
 * Usage: layout <golden dir>; prints one line per check, exits 0 when all agree.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "flexdyn_client.h"

static int failures = 0;

#define SAME(what, a, b, field)                                                                \
    do {                                                                                       \
        if (memcmp(&(a).field, &(b).field, sizeof((a).field)) != 0) {                         \
            fprintf(stderr, "%s: field %s differs\n", what, #field);                           \
            ++failures;                                                                        \
        }                                                                                      \
    } while (0)

static size_t load(const char *dir, const char *name, uint8_t *buf, size_t cap) {
    char path[4096];
    FILE *f;
    size_t n;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "rb");
    if (f == NULL) {
        fprintf(stderr, "cannot open %s\n", path);
        exit(2);
    }
    n = fread(buf, 1, cap, f);
    fclose(f);
    return n;
}

static void same_header(const char *what, fd_header a, fd_header b) {
    SAME(what, a, b, protocol_version);
    SAME(what, a, b, spacecraft_id);
    SAME(what, a, b, tick);
    SAME(what, a, b, sim_time_ns);
    SAME(what, a, b, seq);
}

static void check_sizes(void) {
    static const struct {
        int which;
        size_t c_size;
        const char *name;
    } sizes[] = {
        {FLEXDYN_STRUCT_HEADER, sizeof(fd_header), "fd_header"},
        {FLEXDYN_STRUCT_STATE, sizeof(fd_state_msg), "fd_state_msg"},
        {FLEXDYN_STRUCT_EFFECTOR_STATE, sizeof(fd_effector_state), "fd_effector_state"},
        {FLEXDYN_STRUCT_IMU, sizeof(fd_imu_msg), "fd_imu_msg"},
        {FLEXDYN_STRUCT_STAR_TRACKER, sizeof(fd_star_tracker_msg), "fd_star_tracker_msg"},
        {FLEXDYN_STRUCT_EFFECTOR_INPUT, sizeof(fd_effector_input), "fd_effector_input"},
        {FLEXDYN_STRUCT_STATUS, sizeof(fd_status_msg), "fd_status_msg"},
        {FLEXDYN_STRUCT_TIME, sizeof(fd_time_msg), "fd_time_msg"},
    };
    size_t i;
    for (i = 0; i < sizeof sizes / sizeof sizes[0]; ++i) {
        size_t lib = flexdyn_struct_size(sizes[i].which);
        if (lib != sizes[i].c_size) {
            fprintf(stderr, "sizeof %s: C %zu, library %zu\n", sizes[i].name, sizes[i].c_size,
                    lib);
            ++failures;
        }
    }
    if (flexdyn_struct_size(99) != 0) {
        fprintf(stderr, "flexdyn_struct_size(99) is not 0\n");
        ++failures;
    }
    printf("sizes checked\n");
}

static void check_state(flexdyn_client *c, const char *dir) {
    static uint8_t buf[FD_MAX_MESSAGE_BYTES];
    static fd_effector_state ea[16], eb[16];
    fd_state_msg a, b;
    fd_error e;
    size_t n = load(dir, "state.bin", buf, sizeof buf);
    uint64_t i;
    int rc;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    memset(ea, 0xAA, sizeof ea);
    memset(eb, 0x55, sizeof eb);
    a.effectors = ea;
    a.effectors_capacity = 16;
    b.effectors = eb;
    b.effectors_capacity = 16;
    e = fd_decode_state(buf, n, &a);
    rc = flexdyn_decode_state(c, buf, n, &b);
    if (e.status != FD_OK || rc != FLEXDYN_OK) {
        fprintf(stderr, "state: header %d, library %d (%s)\n", (int)e.status, rc,
                flexdyn_last_error(c));
        ++failures;
        return;
    }
    same_header("state", a.header, b.header);
    SAME("state", a, b, sigma_bn);
    SAME("state", a, b, q_bn);
    SAME("state", a, b, omega_bn_b_rad_s);
    SAME("state", a, b, omega_dot_bn_b_rad_s2);
    SAME("state", a, b, r_bn_n_m);
    SAME("state", a, b, v_bn_n_m_s);
    SAME("state", a, b, nongrav_accel_bn_n_m_s2);
    SAME("state", a, b, orb_energy_j);
    SAME("state", a, b, rot_energy_j);
    SAME("state", a, b, orb_ang_mom_n);
    SAME("state", a, b, rot_ang_mom_c_n);
    SAME("state", a, b, torque_b_nm);
    SAME("state", a, b, force_b_newton);
    SAME("state", a, b, command_flags);
    SAME("state", a, b, n_effectors);
    if (b.effectors != eb || b.effectors_capacity != 16) {
        fprintf(stderr, "state: the library moved the caller's effectors array\n");
        ++failures;
    }
    if (a.n_effectors == 0) {
        fprintf(stderr, "state: the golden state has no effectors to compare\n");
        ++failures;
    }
    for (i = 0; i < a.n_effectors; ++i) {
        /* States and outputs beyond their counts are not part of the message. */
        SAME("effector", ea[i], eb[i], kind);
        SAME("effector", ea[i], eb[i], flags);
        SAME("effector", ea[i], eb[i], n_states);
        SAME("effector", ea[i], eb[i], n_outputs);
        if (memcmp(ea[i].states, eb[i].states, sizeof(double) * (size_t)ea[i].n_states) != 0 ||
            memcmp(ea[i].outputs, eb[i].outputs, sizeof(double) * (size_t)ea[i].n_outputs) != 0) {
            fprintf(stderr, "effector %u: values differ\n", (unsigned)i);
            ++failures;
        }
    }
    /* Too small an array: the library says so (as the header does) and names the counts. */
    b.effectors_capacity = 0;
    rc = flexdyn_decode_state(c, buf, n, &b);
    if (rc != FLEXDYN_ERR_CAPACITY || strstr(flexdyn_last_error(c), "the array holds 0") == NULL) {
        fprintf(stderr, "state with capacity 0: %d (%s)\n", rc, flexdyn_last_error(c));
        ++failures;
    }
    printf("state: %u effectors compared\n", (unsigned)a.n_effectors);
}

/* Declares a and b of `type`, loads `file` and decodes it into a with the header's `fd_fn` and
 * into b with the library's `lib_fn`; returns from the calling check if either fails. */
#define DECODE_BOTH(type, file, fd_fn, lib_fn, what)                                           \
    uint8_t buf[256];                                                                          \
    type a, b;                                                                                 \
    size_t n = load(dir, file, buf, sizeof buf);                                               \
    memset(&a, 0, sizeof a);                                                                   \
    memset(&b, 0, sizeof b);                                                                   \
    if (fd_fn(buf, n, &a).status != FD_OK || lib_fn(c, buf, n, &b) != FLEXDYN_OK) {            \
        fprintf(stderr, "%s: does not decode (%s)\n", what, flexdyn_last_error(c));           \
        ++failures;                                                                            \
        return;                                                                                \
    }                                                                                          \
    same_header(what, a.header, b.header)

static void check_imu(flexdyn_client *c, const char *dir) {
    DECODE_BOTH(fd_imu_msg, "imu.bin", fd_decode_imu, flexdyn_decode_imu, "imu");
    SAME("imu", a, b, omega_p_rad_s);
    SAME("imu", a, b, accel_p_m_s2);
    SAME("imu", a, b, dtheta_p_rad);
    SAME("imu", a, b, dv_p_m_s);
    SAME("imu", a, b, saturation_flags);
    printf("imu compared\n");
}

static void check_star_tracker(flexdyn_client *c, const char *dir) {
    DECODE_BOTH(fd_star_tracker_msg, "star_tracker.bin", fd_decode_star_tracker, flexdyn_decode_star_tracker, "star tracker");
    SAME("star tracker", a, b, q_cn);
    SAME("star tracker", a, b, valid);
    SAME("star tracker", a, b, status_flags);
    printf("star tracker compared\n");
}

static void check_status(flexdyn_client *c, const char *dir) {
    DECODE_BOTH(fd_status_msg, "status.bin", fd_decode_status, flexdyn_decode_status, "status");
    SAME("status", a, b, mode);
    SAME("status", a, b, run_state);
    SAME("status", a, b, lateness_p50_ns);
    SAME("status", a, b, lateness_p99_ns);
    SAME("status", a, b, lateness_max_ns);
    SAME("status", a, b, overrun_count);
    SAME("status", a, b, frames_skipped);
    SAME("status", a, b, last_command_tick);
    SAME("status", a, b, command_age_ns);
    SAME("status", a, b, command_stale);
    SAME("status", a, b, stale_policy);
    SAME("status", a, b, rejected_malformed);
    SAME("status", a, b, rejected_bad_version);
    SAME("status", a, b, rejected_non_finite);
    SAME("status", a, b, rejected_wrong_spacecraft);
    SAME("status", a, b, rejected_stale_tick);
    SAME("status", a, b, rejected_unknown_sender);
    SAME("status", a, b, rejected_bad_effector_input);
    SAME("status", a, b, rejected_wrong_identity);
    SAME("status", a, b, rejected_operator_refused);
    SAME("status", a, b, rejected_fault_refused);
    SAME("status", a, b, rejected_fsw_refused);
    SAME("status", a, b, commands_dropped);
    SAME("status", a, b, wall_time_unix_ns);
    SAME("status", a, b, faults_active);
    SAME("status", a, b, faults_active_bits[0]);
    SAME("status", a, b, faults_active_bits[3]);
    printf("status compared\n");
}

static void check_time(flexdyn_client *c, const char *dir) {
    DECODE_BOTH(fd_time_msg, "time.bin", fd_decode_time, flexdyn_decode_time, "time");
    SAME("time", a, b, run_state);
    SAME("time", a, b, mode);
    SAME("time", a, b, flags);
    SAME("time", a, b, frame_ns);
    SAME("time", a, b, speed);
    SAME("time", a, b, tai_ns_1958);
    SAME("time", a, b, utc_year);
    SAME("time", a, b, utc_month);
    SAME("time", a, b, utc_day);
    SAME("time", a, b, utc_hour);
    SAME("time", a, b, utc_minute);
    SAME("time", a, b, utc_second);
    SAME("time", a, b, utc_nanosecond);
    SAME("time", a, b, tai_minus_utc_s);
    SAME("time", a, b, gps_week);
    SAME("time", a, b, gps_ns_of_week);
    SAME("time", a, b, met_ns);
    SAME("time", a, b, cuc_tai);
    SAME("time", a, b, tone_met);
    SAME("time", a, b, tone_tai);
    printf("time compared\n");
}

/* Bad input is an error code with a message, never a crash. */
static void check_errors(flexdyn_client *c) {
    uint8_t junk[3] = {4, 0, 1};
    fd_imu_msg m;
    int rc = flexdyn_decode_imu(c, junk, sizeof junk, &m);
    if (rc != FLEXDYN_ERR_DECODE || strstr(flexdyn_last_error(c), "undecodable IMU") == NULL) {
        fprintf(stderr, "junk IMU: %d (%s)\n", rc, flexdyn_last_error(c));
        ++failures;
    }
    rc = flexdyn_decode_imu(c, junk, sizeof junk, NULL);
    if (rc != FLEXDYN_ERR_DECODE && rc != FLEXDYN_ERR_ARGUMENT) ++failures;
    rc = flexdyn_poll_state(c, NULL);
    if (rc != FLEXDYN_ERR_ARGUMENT) {
        fprintf(stderr, "poll_state(NULL): %d\n", rc);
        ++failures;
    }
    rc = flexdyn_lockstep_answer_no_command(c);
    if (rc != FLEXDYN_ERR_USAGE || strstr(flexdyn_last_error(c), "not open") == NULL) {
        fprintf(stderr, "answer before open: %d (%s)\n", rc, flexdyn_last_error(c));
        ++failures;
    }
    if (flexdyn_open(NULL, NULL) != FLEXDYN_ERR_ARGUMENT) ++failures;
    printf("errors checked\n");
}

int main(int argc, char **argv) {
    flexdyn_client *c;
    if (argc != 2) {
        fprintf(stderr, "usage: %s <golden dir>\n", argv[0]);
        return 2;
    }
    c = flexdyn_client_new();
    if (c == NULL) return 2;
    check_sizes();
    check_state(c, argv[1]);
    check_imu(c, argv[1]);
    check_star_tracker(c, argv[1]);
    check_status(c, argv[1]);
    check_time(c, argv[1]);
    check_errors(c);
    flexdyn_client_free(c);
    if (failures != 0) {
        fprintf(stderr, "%d differences\n", failures);
        return 1;
    }
    printf("all agree\n");
    return 0;
}
