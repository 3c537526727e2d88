/*
 * The C codec against the golden vectors (proto/golden/<name>.bin, derived by hand from the layout in
 * proto/README.md and pinned by proto/tests/golden.rs): for every message, encoding the values
 * of the golden table gives the golden bytes, and decoding the golden bytes gives those values
 * bit for bit. Then the decoder's error rules on edited copies. Usage: test_golden <golden dir>.
 * Prints one line per check and exits non-zero on the first failure.
 */
#include <stdio.h>
#include <stdlib.h>

#include "flexdyn_proto.h"

static int failures = 0;

#define CHECK(cond, what)                                                                      \
    do {                                                                                       \
        if (!(cond)) {                                                                         \
            fprintf(stderr, "FAIL %s:%d: %s\n", __FILE__, __LINE__, what);                   \
            failures++;                                                                        \
        }                                                                                      \
    } while (0)

static size_t read_file(const char *dir, const char *name, uint8_t *buf, size_t cap) {
    char path[1024];
    FILE *f;
    size_t n;
    snprintf(path, sizeof path, "%s/%s.bin", dir, name);
    f = fopen(path, "rb");
    if (f == NULL) {
        fprintf(stderr, "cannot open %s\n", path);
        exit(2);
    }
    n = fread(buf, 1, cap, f);
    fclose(f);
    return n;
}

static int same_bits(const double *a, const double *b, size_t n) {
    return memcmp(a, b, n * sizeof(double)) == 0;
}

static int same_header(const fd_header *a, const fd_header *b) {
    return a->protocol_version == b->protocol_version && a->spacecraft_id == b->spacecraft_id &&
           a->tick == b->tick && a->sim_time_ns == b->sim_time_ns && a->seq == b->seq;
}

#define SC 0x11223344u

static void check_encoded(const char *name, const uint8_t *golden, size_t golden_len,
                          const uint8_t *enc, size_t enc_len) {
    char what[128];
    snprintf(what, sizeof what, "%s: C encoding equals the golden bytes", name);
    CHECK(enc_len == golden_len && memcmp(enc, golden, golden_len) == 0, what);
    printf("%s: encode %s\n", name, enc_len == golden_len ? "ok" : "length differs");
}

static void test_state(const char *dir) {
    uint8_t golden[1024], enc[1024];
    size_t n = read_file(dir, "state", golden, sizeof golden);
    fd_effector_state eff[2], back_eff[4];
    fd_state_msg m, back;
    fd_error e;
    double sigma[3] = {0.125, -0.25, 0.5}, q[4] = {0.875, 0.25, -0.375, 0.1875};
    memset(&m, 0, sizeof m);
    memset(eff, 0, sizeof eff);
    m.header = fd_header_new(SC, 0x0102030405060708u, 1500000000u, 0x102u);
    memcpy(m.sigma_bn, sigma, sizeof sigma);
    memcpy(m.q_bn, q, sizeof q);
    m.omega_bn_b_rad_s[0] = 1.0 / 1024.0;
    m.omega_bn_b_rad_s[1] = -2.0 / 1024.0;
    m.omega_bn_b_rad_s[2] = 4.0 / 1024.0;
    m.omega_dot_bn_b_rad_s2[0] = 1.5;
    m.omega_dot_bn_b_rad_s2[1] = -3.0;
    m.omega_dot_bn_b_rad_s2[2] = 6.0;
    m.r_bn_n_m[0] = 7000000.0;
    m.r_bn_n_m[1] = -1024.0;
    m.r_bn_n_m[2] = 0.5;
    m.v_bn_n_m_s[0] = 0.25;
    m.v_bn_n_m_s[1] = 7500.0;
    m.v_bn_n_m_s[2] = -8.0;
    m.nongrav_accel_bn_n_m_s2[0] = 0.0;
    m.nongrav_accel_bn_n_m_s2[1] = -0.0;
    m.nongrav_accel_bn_n_m_s2[2] = 1.0 / 1048576.0;
    m.orb_energy_j = -2.5e10;
    m.rot_energy_j = 12.5;
    m.orb_ang_mom_n[0] = 1.0e12;
    m.orb_ang_mom_n[1] = -2.0;
    m.orb_ang_mom_n[2] = 4.0;
    m.rot_ang_mom_c_n[0] = 100.0;
    m.rot_ang_mom_c_n[1] = -0.75;
    m.rot_ang_mom_c_n[2] = 1.25;
    m.torque_b_nm[0] = 0.0625;
    m.torque_b_nm[1] = -0.125;
    m.torque_b_nm[2] = 0.25;
    m.force_b_newton[0] = 1.0;
    m.force_b_newton[1] = -2.0;
    m.force_b_newton[2] = 3.0;
    m.command_flags = FD_COMMAND_FLAG_STALE | FD_COMMAND_FLAG_NO_COMMAND_YET;
    eff[0].kind = FD_EFFECTOR_PANEL_PAIR;
    eff[0].n_states = 4;
    eff[0].states[0] = 0.5;
    eff[0].states[1] = -0.0625;
    eff[0].states[2] = 1.25;
    eff[0].states[3] = 0.03125;
    eff[1].kind = FD_EFFECTOR_REACTION_WHEEL;
    eff[1].flags = FD_WHEEL_TORQUE_LIMITED | FD_WHEEL_SPEED_LIMITED;
    eff[1].n_states = 1;
    eff[1].states[0] = -150.5;
    eff[1].n_outputs = 2;
    eff[1].outputs[0] = 0.25;
    eff[1].outputs[1] = -0.0078125;
    m.effectors = eff;
    m.n_effectors = 2;
    m.effectors_capacity = 2;
    check_encoded("StateMsg", golden, n, enc, fd_encode_state(&m, enc, sizeof enc));

    memset(&back, 0, sizeof back);
    back.effectors = back_eff;
    back.effectors_capacity = 4;
    e = fd_decode_state(golden, n, &back);
    CHECK(e.status == FD_OK, "StateMsg decodes");
    CHECK(same_header(&back.header, &m.header), "StateMsg header");
    CHECK(same_bits(back.sigma_bn, m.sigma_bn, 3) && same_bits(back.q_bn, m.q_bn, 4) &&
              same_bits(back.omega_bn_b_rad_s, m.omega_bn_b_rad_s, 3) &&
              same_bits(back.omega_dot_bn_b_rad_s2, m.omega_dot_bn_b_rad_s2, 3) &&
              same_bits(back.r_bn_n_m, m.r_bn_n_m, 3) &&
              same_bits(back.v_bn_n_m_s, m.v_bn_n_m_s, 3) &&
              same_bits(back.nongrav_accel_bn_n_m_s2, m.nongrav_accel_bn_n_m_s2, 3) &&
              same_bits(&back.orb_energy_j, &m.orb_energy_j, 1) &&
              same_bits(&back.rot_energy_j, &m.rot_energy_j, 1) &&
              same_bits(back.orb_ang_mom_n, m.orb_ang_mom_n, 3) &&
              same_bits(back.rot_ang_mom_c_n, m.rot_ang_mom_c_n, 3) &&
              same_bits(back.torque_b_nm, m.torque_b_nm, 3) &&
              same_bits(back.force_b_newton, m.force_b_newton, 3),
          "StateMsg fields bit for bit (including -0.0)");
    CHECK(back.command_flags == 5 && back.n_effectors == 2, "StateMsg flags and count");
    CHECK(back_eff[0].kind == 1 && back_eff[0].n_states == 4 && back_eff[0].n_outputs == 0 &&
              same_bits(back_eff[0].states, eff[0].states, 4),
          "StateMsg panel pair");
    CHECK(back_eff[1].kind == 2 && back_eff[1].flags == 3 && back_eff[1].n_states == 1 &&
              back_eff[1].n_outputs == 2 && same_bits(back_eff[1].states, eff[1].states, 1) &&
              same_bits(back_eff[1].outputs, eff[1].outputs, 2),
          "StateMsg wheel");
    /* Too little storage: the wire rules pass, the caller's array is too small. */
    back.effectors_capacity = 1;
    e = fd_decode_state(golden, n, &back);
    CHECK(e.status == FD_ERR_CAPACITY && e.needed == 2, "StateMsg capacity");
    back.effectors_capacity = 4;
    /* Truncated inside the second effector's state count: needed = that count's end. */
    e = fd_decode_state(golden, 389, &back);
    CHECK(e.status == FD_ERR_LENGTH && e.needed == 395 && e.actual == 389, "StateMsg walk");
    e = fd_decode_state(golden, 100, &back);
    CHECK(e.status == FD_ERR_LENGTH && e.needed == FD_STATE_FIXED_LEN, "StateMsg short");
    printf("StateMsg: decode ok\n");
}

static void test_imu_and_star_tracker(const char *dir) {
    uint8_t golden[256], enc[256];
    size_t n = read_file(dir, "imu", golden, sizeof golden);
    fd_imu_msg m, back;
    fd_star_tracker_msg s, sback;
    double q[4] = {0.875, 0.25, -0.375, 0.1875};
    fd_error e;
    memset(&m, 0, sizeof m);
    m.header = fd_header_new(SC, 9, 9000000u, 10);
    m.omega_p_rad_s[0] = 1.0 / 1024.0;
    m.omega_p_rad_s[1] = -0.5;
    m.omega_p_rad_s[2] = 2.0;
    m.accel_p_m_s2[0] = 0.0;
    m.accel_p_m_s2[1] = 9.75;
    m.accel_p_m_s2[2] = -0.125;
    m.dtheta_p_rad[0] = 1.0 / 1048576.0;
    m.dtheta_p_rad[1] = -2.0 / 1048576.0;
    m.dtheta_p_rad[2] = 4.0 / 1048576.0;
    m.dv_p_m_s[0] = 0.001;
    m.dv_p_m_s[1] = -1.5;
    m.dv_p_m_s[2] = 3.0;
    m.saturation_flags = FD_SATURATION_GYRO_RATE | FD_SATURATION_DV;
    check_encoded("ImuMsg", golden, n, enc, fd_encode_imu(&m, enc, sizeof enc));
    e = fd_decode_imu(golden, n, &back);
    CHECK(e.status == FD_OK && same_header(&back.header, &m.header) &&
              same_bits(back.omega_p_rad_s, m.omega_p_rad_s, 3) &&
              same_bits(back.accel_p_m_s2, m.accel_p_m_s2, 3) &&
              same_bits(back.dtheta_p_rad, m.dtheta_p_rad, 3) &&
              same_bits(back.dv_p_m_s, m.dv_p_m_s, 3) && back.saturation_flags == 0x09,
          "ImuMsg decodes to the table");

    n = read_file(dir, "star_tracker", golden, sizeof golden);
    memset(&s, 0, sizeof s);
    s.header = fd_header_new(SC, 11, 110000000u, 12);
    memcpy(s.q_cn, q, sizeof q);
    s.valid = 0;
    s.status_flags = FD_STAR_TRACKER_SUN_EXCLUSION;
    check_encoded("StarTrackerMsg", golden, n, enc, fd_encode_star_tracker(&s, enc, sizeof enc));
    e = fd_decode_star_tracker(golden, n, &sback);
    CHECK(e.status == FD_OK && same_header(&sback.header, &s.header) &&
              same_bits(sback.q_cn, q, 4) && sback.valid == 0 && sback.status_flags == 1,
          "StarTrackerMsg decodes to the table");
    golden[62] = 2;
    e = fd_decode_star_tracker(golden, n, &sback);
    CHECK(e.status == FD_ERR_MALFORMED, "StarTrackerMsg bool other than 0/1");
    printf("ImuMsg, StarTrackerMsg: decode ok\n");
}

static void test_magnetometer(const char *dir) {
    uint8_t golden[256], enc[256];
    size_t n = read_file(dir, "magnetometer", golden, sizeof golden);
    fd_magnetometer_msg m, back;
    double b[3] = {1.0 / 32768.0, -1.0 / 65536.0, -0.0};
    fd_error e;
    memset(&m, 0, sizeof m);
    m.header = fd_header_new(SC, 13, 130000000u, 1);
    memcpy(m.b_s_t, b, sizeof b);
    m.saturation_flags = FD_MAGNETOMETER_AXIS_1 | FD_MAGNETOMETER_AXIS_3;
    check_encoded("MagnetometerMsg", golden, n, enc, fd_encode_magnetometer(&m, enc, sizeof enc));
    e = fd_decode_magnetometer(golden, n, &back);
    CHECK(e.status == FD_OK && same_header(&back.header, &m.header) &&
              same_bits(back.b_s_t, b, 3) && back.saturation_flags == 0x05,
          "MagnetometerMsg decodes to the table");
    e = fd_decode_magnetometer(golden, n - 1, &back);
    CHECK(e.status == FD_ERR_LENGTH && e.needed == FD_MAGNETOMETER_LEN, "MagnetometerMsg short");
    printf("MagnetometerMsg: decode ok\n");
}

static void test_sun_sensors(const char *dir) {
    uint8_t golden[256], enc[256];
    size_t n = read_file(dir, "css", golden, sizeof golden);
    fd_css_msg c, cback;
    fd_fss_msg f, fback;
    double r[3] = {0.5, 0.75, 1.0 / 1024.0}, zero[13] = {0.0};
    fd_error e;
    memset(&c, 0, sizeof c);
    c.header = fd_header_new(SC, 13, 130000000u, 1);
    c.detector_count = 3;
    memcpy(c.readings, r, sizeof r);
    check_encoded("CssMsg", golden, n, enc, fd_encode_css(&c, enc, sizeof enc));
    e = fd_decode_css(golden, n, &cback);
    CHECK(e.status == FD_OK && same_header(&cback.header, &c.header) &&
              cback.detector_count == 3 && same_bits(cback.readings, r, 3) &&
              same_bits(cback.readings + 3, zero, 13),
          "CssMsg decodes to the table");
    e = fd_decode_css(golden, n - 1, &cback);
    CHECK(e.status == FD_ERR_LENGTH && e.needed == FD_CSS_LEN, "CssMsg short");
    golden[30] = FD_MAX_CSS_DETECTORS + 1u;
    e = fd_decode_css(golden, n, &cback);
    CHECK(e.status == FD_ERR_MALFORMED, "CssMsg detector count above the maximum");
    n = read_file(dir, "fss", golden, sizeof golden);
    memset(&f, 0, sizeof f);
    f.header = fd_header_new(SC, 13, 130000000u, 1);
    f.alpha_rad = 0.125;
    f.beta_rad = -0.0625;
    f.flags = FD_FSS_VALID | FD_FSS_IN_FOV | FD_FSS_SUNLIT;
    check_encoded("FssMsg", golden, n, enc, fd_encode_fss(&f, enc, sizeof enc));
    e = fd_decode_fss(golden, n, &fback);
    CHECK(e.status == FD_OK && same_header(&fback.header, &f.header) &&
              same_bits(&fback.alpha_rad, &f.alpha_rad, 1) &&
              same_bits(&fback.beta_rad, &f.beta_rad, 1) && fback.flags == 0x07,
          "FssMsg decodes to the table");
    printf("CssMsg, FssMsg: decode ok\n");
}

static void test_commands(const char *dir) {
    uint8_t golden[256], enc[256];
    size_t n;
    fd_command_msg m, back;
    fd_effector_input in[2], back_in[4];
    fd_error e;

    /* Wrench */
    n = read_file(dir, "command_wrench", golden, sizeof golden);
    memset(&m, 0, sizeof m);
    m.header = fd_header_new(SC, 42, 420000000u, 7);
    m.sender_id = 0xDEADBEEFu;
    m.kind = FD_COMMAND_WRENCH;
    m.torque_b_nm[0] = 0.0625;
    m.torque_b_nm[1] = -0.125;
    m.torque_b_nm[2] = 0.25;
    m.force_b_newton[0] = -1.0;
    m.force_b_newton[1] = 0.0;
    m.force_b_newton[2] = 0.5;
    check_encoded("CommandMsg::Wrench", golden, n, enc, fd_encode_command(&m, enc, sizeof enc));
    memset(&back, 0, sizeof back);
    back.inputs = back_in;
    back.inputs_capacity = 4;
    e = fd_decode_command(golden, n, &back);
    CHECK(e.status == FD_OK && back.kind == FD_COMMAND_WRENCH && back.sender_id == 0xDEADBEEFu &&
              same_header(&back.header, &m.header) &&
              same_bits(back.torque_b_nm, m.torque_b_nm, 3) &&
              same_bits(back.force_b_newton, m.force_b_newton, 3),
          "Wrench decodes to the table");
    /* A NaN torque is named like Rust's DecodeError::NonFinite. */
    fd_put_u64(golden + 38 + 16, 0x7ff8000000000000u); /* a quiet NaN */
    e = fd_decode_command(golden, n, &back);
    CHECK(e.status == FD_ERR_NON_FINITE && e.field != NULL &&
              strcmp(e.field, "kind.torque_b_nm[2]") == 0,
          "NaN torque named");
    /* Tag 1 with a wrench body: trailing bytes; tag 3: malformed. */
    n = read_file(dir, "command_wrench", golden, sizeof golden);
    golden[34] = 1;
    e = fd_decode_command(golden, n, &back);
    CHECK(e.status == FD_ERR_TRAILING_BYTES && e.needed == 38 && e.actual == 86, "tag 1, 86 bytes");
    golden[34] = 3;
    e = fd_decode_command(golden, n, &back);
    CHECK(e.status == FD_ERR_MALFORMED, "tag 3");
    golden[0] = 2;
    e = fd_decode_command(golden, n, &back);
    CHECK(e.status == FD_ERR_UNKNOWN_VERSION && e.found_version == 2, "version checked first");

    /* Actuators */
    n = read_file(dir, "command_actuators", golden, sizeof golden);
    memset(&m, 0, sizeof m);
    memset(in, 0, sizeof in);
    m.header = fd_header_new(SC, 44, 440000000u, 9);
    m.sender_id = 7;
    m.kind = FD_COMMAND_ACTUATORS;
    m.torque_b_nm[0] = 0.5;
    m.torque_b_nm[1] = -0.25;
    m.torque_b_nm[2] = 0.0;
    m.force_b_newton[2] = -0.0;
    in[0].effector_index = 2;
    in[0].n_values = 1;
    in[0].values[0] = 0.0625;
    in[1].effector_index = 5;
    in[1].n_values = 1;
    in[1].values[0] = -0.03125;
    m.inputs = in;
    m.n_inputs = 2;
    check_encoded("CommandMsg::Actuators", golden, n, enc, fd_encode_command(&m, enc, sizeof enc));
    e = fd_decode_command(golden, n, &back);
    CHECK(e.status == FD_OK && back.kind == FD_COMMAND_ACTUATORS && back.n_inputs == 2 &&
              back_in[0].effector_index == 2 && back_in[1].effector_index == 5 &&
              same_bits(back_in[0].values, in[0].values, 1) &&
              same_bits(back_in[1].values, in[1].values, 1) &&
              same_bits(back.force_b_newton, m.force_b_newton, 3),
          "Actuators decodes to the table (including -0.0)");
    e = fd_decode_command(golden, n - 3, &back);
    CHECK(e.status == FD_ERR_LENGTH && e.needed == n, "Actuators truncated");

    /* NoCommand */
    n = read_file(dir, "command_no_command", golden, sizeof golden);
    memset(&m, 0, sizeof m);
    m.header = fd_header_new(SC, 43, 430000000u, 8);
    m.sender_id = 5;
    m.kind = FD_COMMAND_NO_COMMAND;
    check_encoded("CommandMsg::NoCommand", golden, n, enc, fd_encode_command(&m, enc, sizeof enc));
    e = fd_decode_command(golden, n, &back);
    CHECK(e.status == FD_OK && back.kind == FD_COMMAND_NO_COMMAND && back.sender_id == 5,
          "NoCommand decodes");
    printf("CommandMsg: decode ok\n");
}

static void test_status(const char *dir) {
    uint8_t golden[256], enc[256];
    size_t n = read_file(dir, "status", golden, sizeof golden);
    fd_status_msg m, back;
    fd_error e;
    memset(&m, 0, sizeof m);
    m.header = fd_header_new(SC, 0x0102030405060708u, 1500000000u, 99);
    m.mode = FD_MODE_LOCKSTEP;
    m.run_state = FD_RUN_STATE_RUNNING;
    m.lateness_p50_ns = 1000;
    m.lateness_p99_ns = 250000;
    m.lateness_max_ns = 3000000;
    m.overrun_count = 3;
    m.frames_skipped = 2;
    m.last_command_tick = 41;
    m.command_age_ns = 1000000;
    m.command_stale = 1;
    m.stale_policy = FD_STALE_POLICY_ZERO;
    m.rejected_malformed = 1;
    m.rejected_bad_version = 2;
    m.rejected_non_finite = 3;
    m.rejected_wrong_spacecraft = 4;
    m.rejected_stale_tick = 5;
    m.rejected_unknown_sender = 6;
    m.rejected_bad_effector_input = 8;
    m.rejected_wrong_identity = 9;
    m.rejected_operator_refused = 10;
    m.rejected_fault_refused = 11;
    m.rejected_fsw_refused = 12;
    m.commands_dropped = 7;
    m.wall_time_unix_ns = 1700000000123456789u;
    m.faults_active = 3;
    m.faults_active_bits[0] = 5u;
    m.faults_active_bits[3] = 0x8000000000000000u;
    check_encoded("StatusMsg", golden, n, enc, fd_encode_status(&m, enc, sizeof enc));
    e = fd_decode_status(golden, n, &back);
    CHECK(e.status == FD_OK && same_header(&back.header, &m.header) &&
              back.wall_time_unix_ns == m.wall_time_unix_ns &&
              back.rejected_bad_effector_input == 8 && back.rejected_wrong_identity == 9 &&
              back.rejected_operator_refused == 10 && back.commands_dropped == 7 &&
              back.stale_policy == 1 && back.command_stale == 1 &&
              back.rejected_fault_refused == 11 && back.rejected_fsw_refused == 12 &&
              back.faults_active == 3 &&
              back.faults_active_bits[0] == 5u && back.faults_active_bits[1] == 0u &&
              back.faults_active_bits[3] == 0x8000000000000000u,
          "StatusMsg decodes to the table");
    golden[34] = FD_RUN_STATE_PAUSED;
    e = fd_decode_status(golden, n, &back);
    CHECK(e.status == FD_OK && back.run_state == 6, "run_state tag 6 (Paused) is valid");
    golden[34] = 7;
    e = fd_decode_status(golden, n, &back);
    CHECK(e.status == FD_ERR_MALFORMED, "run_state tag 7");
    printf("StatusMsg: decode ok\n");
}

/* TIME_GOLDEN of proto/tests/golden.rs: 2016-12-31T23:59:60.25 UTC, paused at tick 6. */
static void test_time(const char *dir) {
    uint8_t golden[256], enc[256];
    size_t n = read_file(dir, "time", golden, sizeof golden);
    static const uint8_t cuc[8] = {0x1F, 0x6E, 0xFA, 0xA5, 0x24, 0x40, 0x00, 0x00};
    fd_time_msg m, back;
    fd_error e;
    char key[64];
    memset(&m, 0, sizeof m);
    m.header = fd_header_new(SC, 6, 750000000u, 6);
    m.run_state = FD_RUN_STATE_PAUSED;
    m.mode = FD_MODE_REAL_TIME;
    m.flags = FD_TIME_EPOCH_VALID | FD_TIME_LEAP_SECOND;
    m.frame_ns = 125000000u;
    m.speed = 0.5;
    m.tai_ns_1958 = 1861920036250000000u;
    m.utc_year = 2016;
    m.utc_month = 12;
    m.utc_day = 31;
    m.utc_hour = 23;
    m.utc_minute = 59;
    m.utc_second = 60;
    m.utc_nanosecond = 250000000u;
    m.tai_minus_utc_s = 36;
    m.gps_week = 1930;
    m.gps_ns_of_week = 17250000000u;
    m.met_ns = 750000000u;
    memcpy(m.cuc_tai, cuc, 8);
    m.tone_met.subseconds = 0x80000000u;
    m.tone_tai.seconds = 1861920036u;
    CHECK(n == FD_TIME_LEN, "time.bin length");
    check_encoded("TimeMsg", golden, n, enc, fd_encode_time(&m, enc, sizeof enc));
    e = fd_decode_time(golden, n, &back);
    CHECK(e.status == FD_OK && same_header(&back.header, &m.header) && back.run_state == 6 &&
              back.flags == 5 && back.speed == 0.5 && back.utc_second == 60 &&
              back.tai_minus_utc_s == 36 && back.gps_week == 1930 &&
              back.gps_ns_of_week == m.gps_ns_of_week && back.tai_ns_1958 == m.tai_ns_1958 &&
              memcmp(back.cuc_tai, cuc, 8) == 0 && back.tone_met.subseconds == 0x80000000u &&
              back.tone_tai.seconds == 1861920036u,
          "TimeMsg decodes to the table");
    /* A negative leap-second count survives the round trip (two's complement). */
    m.tai_minus_utc_s = -2;
    fd_encode_time(&m, enc, sizeof enc);
    CHECK(enc[74] == 0xFE && enc[77] == 0xFF, "i32 -2 on the wire");
    e = fd_decode_time(enc, FD_TIME_LEN, &back);
    CHECK(e.status == FD_OK && back.tai_minus_utc_s == -2, "i32 -2 decodes");
    golden[30] = 7;
    e = fd_decode_time(golden, n, &back);
    CHECK(e.status == FD_ERR_MALFORMED, "TimeMsg run_state tag 7");
    e = fd_decode_time(golden, n - 1, &back);
    CHECK(e.status == FD_ERR_LENGTH && e.needed == FD_TIME_LEN, "TimeMsg short");
    CHECK(fd_time_key(key, sizeof key, "sc1") > 0 && strcmp(key, "flexdyn/sc1/tlm/time") == 0,
          "time key");
    printf("TimeMsg: ok\n");
}

/* OPERATOR_GOLDEN of proto/tests/golden.rs: run 0x1_0000_0005 ticks, then hold. */
static void test_operator(const char *dir) {
    uint8_t golden[64], enc[64];
    size_t n = read_file(dir, "operator", golden, sizeof golden);
    fd_operator_msg m, back;
    fd_error e;
    char key[64];
    memset(&m, 0, sizeof m);
    m.header = fd_header_new(SC, 44, 440000000u, 3);
    m.action = FD_OPERATOR_RUN_TICKS;
    m.ticks = 0x100000005u;
    CHECK(n == FD_OPERATOR_LEN, "operator.bin length");
    check_encoded("OperatorMsg", golden, n, enc, fd_encode_operator(&m, enc, sizeof enc));
    e = fd_decode_operator(golden, n, &back);
    CHECK(e.status == FD_OK && same_header(&back.header, &m.header) && back.action == 2 &&
              back.ticks == m.ticks,
          "OperatorMsg decodes to the table");
    golden[30] = 4;
    e = fd_decode_operator(golden, n, &back);
    CHECK(e.status == FD_ERR_MALFORMED, "OperatorMsg action tag 4");
    e = fd_decode_operator(golden, n - 1, &back);
    CHECK(e.status == FD_ERR_LENGTH && e.needed == FD_OPERATOR_LEN, "OperatorMsg short");
    CHECK(fd_operator_key(key, sizeof key, "sc1") > 0 && strcmp(key, "flexdyn/sc1/operator") == 0,
          "operator key");
    /* OPERATOR_CHECKPOINT_GOLDEN (protocol 12): save a checkpoint at tick 1000. */
    n = read_file(dir, "operator_checkpoint", golden, sizeof golden);
    memset(&m, 0, sizeof m);
    m.header = fd_header_new(SC, 44, 440000000u, 4);
    m.action = FD_OPERATOR_CHECKPOINT;
    m.ticks = 1000u;
    CHECK(n == FD_OPERATOR_LEN, "operator_checkpoint.bin length");
    check_encoded("OperatorMsg (Checkpoint)", golden, n, enc,
                  fd_encode_operator(&m, enc, sizeof enc));
    e = fd_decode_operator(golden, n, &back);
    CHECK(e.status == FD_OK && same_header(&back.header, &m.header) && back.action == 3 &&
              back.ticks == 1000u,
          "OperatorMsg (Checkpoint) decodes to the table");
    m.action = FD_OPERATOR_CHECKPOINT + 1;
    CHECK(fd_encode_operator(&m, enc, sizeof enc) == 0, "OperatorMsg action 4 is not encoded");
    printf("OperatorMsg: ok\n");
}

/* FAULT_EVENT_GOLDEN and FAULT_COMMAND_GOLDEN of proto/tests/golden.rs (protocol 8). */
static void test_faults(const char *dir) {
    uint8_t golden[256], enc[256];
    size_t n = read_file(dir, "fault_event", golden, sizeof golden);
    fd_fault_event_msg ev, ev_back;
    fd_fault_command_msg cmd, cmd_back;
    fd_error e;
    char key[64];
    const char *gyro = "imus.hub.gyro", *rw2 = "reaction_wheels.rw2";
    memset(&ev, 0, sizeof ev);
    ev.header = fd_header_new(SC, 44, 440000000u, 1);
    ev.fault_index = 3;
    ev.source = FD_FAULT_SOURCE_LIVE;
    ev.mode = 2;
    ev.active = 1;
    ev.edge_ns = 440000000u;
    ev.axes = 5;
    ev.params[0] = 0.25;
    memcpy(ev.target, gyro, strlen(gyro));
    CHECK(n == FD_FAULT_EVENT_LEN, "fault_event.bin length");
    check_encoded("FaultEventMsg", golden, n, enc, fd_encode_fault_event(&ev, enc, sizeof enc));
    e = fd_decode_fault_event(golden, n, &ev_back);
    CHECK(e.status == FD_OK && same_header(&ev_back.header, &ev.header) &&
              ev_back.fault_index == 3 && ev_back.source == 1 && ev_back.mode == 2 &&
              ev_back.active == 1 && ev_back.edge_ns == 440000000u && ev_back.axes == 5 &&
              ev_back.params[0] == 0.25 && memcmp(ev_back.target, ev.target, FD_FAULT_TARGET_LEN) == 0,
          "FaultEventMsg decodes to the table");
    golden[34] = 3;
    CHECK(fd_decode_fault_event(golden, n, &ev_back).status == FD_ERR_MALFORMED, "source tag 3");
    golden[34] = 1;
    golden[42] = 2;
    CHECK(fd_decode_fault_event(golden, n, &ev_back).status == FD_ERR_MALFORMED, "active = 2");
    golden[42] = 1;
    /* The text rule: "imus.hub.gyro" (13 bytes at 71), NULs, then 0x80 in the last byte. */
    golden[71 + 127] = 0x80;
    CHECK(fd_decode_fault_event(golden, n, &ev_back).status == FD_ERR_MALFORMED,
          "a byte after the target's NUL");
    golden[71 + 127] = 0;
    memset(golden + 71, 'x', FD_FAULT_TARGET_LEN);
    CHECK(fd_decode_fault_event(golden, n, &ev_back).status == FD_OK,
          "a target of 128 bytes (no NUL)");

    n = read_file(dir, "fault_command", golden, sizeof golden);
    memset(&cmd, 0, sizeof cmd);
    cmd.header = fd_header_new(SC, 44, 440000000u, 2);
    cmd.action = FD_FAULT_INJECT;
    cmd.at_tick = 0x100000005u;
    cmd.mode = 10;
    cmd.params[0] = 0.5;
    cmd.duration_ns = 2000000000u;
    cmd.seed = 7;
    memcpy(cmd.target, rw2, strlen(rw2));
    CHECK(n == FD_FAULT_COMMAND_LEN, "fault_command.bin length");
    check_encoded("FaultCommandMsg", golden, n, enc,
                  fd_encode_fault_command(&cmd, enc, sizeof enc));
    e = fd_decode_fault_command(golden, n, &cmd_back);
    CHECK(e.status == FD_OK && same_header(&cmd_back.header, &cmd.header) &&
              cmd_back.action == 0 && cmd_back.at_tick == 0x100000005u && cmd_back.mode == 10 &&
              cmd_back.params[0] == 0.5 && cmd_back.duration_ns == 2000000000u &&
              cmd_back.seed == 7 && memcmp(cmd_back.target, cmd.target, FD_FAULT_TARGET_LEN) == 0,
          "FaultCommandMsg decodes to the table");
    golden[30] = 2;
    CHECK(fd_decode_fault_command(golden, n, &cmd_back).status == FD_ERR_MALFORMED,
          "action tag 2");
    golden[30] = 0;
    golden[86 + 20] = 0x80; /* after "reaction_wheels.rw2" and its NUL */
    CHECK(fd_decode_fault_command(golden, n, &cmd_back).status == FD_ERR_MALFORMED,
          "a byte after the target's NUL");
    golden[65] = 0x7f;
    golden[64] = 0xf0; /* and params[1] = +inf: the text (step 4) is reported first */
    CHECK(fd_decode_fault_command(golden, n, &cmd_back).status == FD_ERR_MALFORMED,
          "the text rule before the finite check");
    golden[86 + 20] = 0;
    golden[65] = 0x7f;
    golden[64] = 0xf0; /* params[1] = +inf */
    e = fd_decode_fault_command(golden, n, &cmd_back);
    CHECK(e.status == FD_ERR_NON_FINITE && strcmp(e.field, "params[1]") == 0, "params[1] inf");
    CHECK(fd_fault_key(key, sizeof key, "sc1") > 0 && strcmp(key, "flexdyn/sc1/fault") == 0,
          "fault key");
    CHECK(fd_fault_event_key(key, sizeof key, "sc1") > 0 &&
              strcmp(key, "flexdyn/sc1/tlm/fault") == 0,
          "fault event key");
    printf("FaultEventMsg, FaultCommandMsg: ok\n");
}

static void test_environment(const char *dir) {
    uint8_t golden[512], enc[512];
    size_t n = read_file(dir, "environment", golden, sizeof golden);
    fd_environment_msg m, back;
    /* The EnvironmentMsg table of proto/tests/golden.rs (dyadic values, one -0.0). */
    static const double b_n[3] = {1.0 / 32768.0, -1.0 / 65536.0, 1.0 / 131072.0};
    static const double b_b[3] = {-0.0, 1.0 / 16384.0, -1.0 / 262144.0};
    static const double sun_n[3] = {0.5, -0.5, 0.75}, sun_b[3] = {0.25, 1.0, -0.125};
    static const double moon_n[3] = {-1.0, 0.375, 0.0625};
    static const double gg_t[3] = {1.0 / 1048576.0, -1.0 / 2097152.0, 1.0 / 4194304.0};
    static const double gg_f[3] = {1.0 / 1073741824.0, 0.0, -1.0 / 2147483648.0};
    static const double drag_t[3] = {1.5, -2.5, 3.5}, drag_f[3] = {4.0, -8.0, 16.0};
    static const double srp_t[3] = {1.0 / 16777216.0, 1.0 / 33554432.0, 1.0 / 67108864.0};
    static const double srp_f[3] = {-1.0 / 16777216.0, -1.0 / 33554432.0, -1.0 / 67108864.0};
    static const double dip_t[3] = {0.125, -0.25, 1.0 / 128.0}, zero[3] = {0.0, 0.0, 0.0};
    fd_error e;
    memset(&m, 0, sizeof m);
    m.header = fd_header_new(SC, 17, 170000000u, 2);
    m.tai_ns_1958 = 0x0102030405060708ull;
    m.flags = FD_ENVIRONMENT_EPOCH_VALID | FD_ENVIRONMENT_MAGNETIC | FD_ENVIRONMENT_SUN |
              FD_ENVIRONMENT_SHADOW | FD_ENVIRONMENT_ATMOSPHERE | FD_ENVIRONMENT_ALBEDO;
    m.eclipse = FD_ECLIPSE_PENUMBRA;
    memcpy(m.b_n_t, b_n, sizeof b_n);
    memcpy(m.b_b_t, b_b, sizeof b_b);
    memcpy(m.sun_n, sun_n, sizeof sun_n);
    memcpy(m.sun_b, sun_b, sizeof sun_b);
    memcpy(m.moon_n, moon_n, sizeof moon_n);
    m.shadow_factor = 0.625;
    m.density_kg_m3 = 1.0 / 1099511627776.0; /* 2^-40 */
    memcpy(m.gravity_gradient.torque_b_nm, gg_t, sizeof gg_t);
    memcpy(m.gravity_gradient.force_b_newton, gg_f, sizeof gg_f);
    memcpy(m.drag.torque_b_nm, drag_t, sizeof drag_t);
    memcpy(m.drag.force_b_newton, drag_f, sizeof drag_f);
    memcpy(m.solar_pressure.torque_b_nm, srp_t, sizeof srp_t);
    memcpy(m.solar_pressure.force_b_newton, srp_f, sizeof srp_f);
    memcpy(m.residual_dipole.torque_b_nm, dip_t, sizeof dip_t);
    memcpy(m.residual_dipole.force_b_newton, zero, sizeof zero);
    m.albedo_nadir_w_m2 = 0.171875; /* 11/64 */
    check_encoded("EnvironmentMsg", golden, n, enc, fd_encode_environment(&m, enc, sizeof enc));
    e = fd_decode_environment(golden, n, &back);
    CHECK(e.status == FD_OK && same_header(&back.header, &m.header) &&
              back.tai_ns_1958 == m.tai_ns_1958 && back.flags == 0x77 && back.eclipse == 1 &&
              same_bits(back.b_n_t, b_n, 3) && same_bits(back.b_b_t, b_b, 3) &&
              same_bits(back.sun_n, sun_n, 3) && same_bits(back.sun_b, sun_b, 3) &&
              same_bits(back.moon_n, moon_n, 3) && same_bits(&back.shadow_factor, &m.shadow_factor, 1) &&
              same_bits(&back.density_kg_m3, &m.density_kg_m3, 1) &&
              same_bits(back.gravity_gradient.torque_b_nm, gg_t, 3) &&
              same_bits(back.gravity_gradient.force_b_newton, gg_f, 3) &&
              same_bits(back.drag.torque_b_nm, drag_t, 3) &&
              same_bits(back.drag.force_b_newton, drag_f, 3) &&
              same_bits(back.solar_pressure.torque_b_nm, srp_t, 3) &&
              same_bits(back.solar_pressure.force_b_newton, srp_f, 3) &&
              same_bits(back.residual_dipole.torque_b_nm, dip_t, 3) &&
              same_bits(back.residual_dipole.force_b_newton, zero, 3) &&
              same_bits(&back.albedo_nadir_w_m2, &m.albedo_nadir_w_m2, 1),
          "EnvironmentMsg decodes to the table");
    e = fd_decode_environment(golden, n - 1, &back);
    CHECK(e.status == FD_ERR_LENGTH && e.needed == FD_ENVIRONMENT_LEN, "EnvironmentMsg short");
    printf("EnvironmentMsg: decode ok\n");
}

/* GpsMsg (protocol 7): the GPS_GOLDEN table of proto/tests/golden.rs. */
static void test_gps(const char *dir) {
    uint8_t golden[256], enc[256];
    size_t n = read_file(dir, "gps", golden, sizeof golden);
    fd_gps_msg m, back;
    static const double r_e[3] = {1.5, -2.0, 0.25}, v_e[3] = {0.5, -0.0, 4.0};
    static const double r_n[3] = {8.0, 0.125, -1.0}, v_n[3] = {3.0, -0.5, 1024.0};
    char key[128];
    fd_error e;
    memset(&m, 0, sizeof m);
    m.header = fd_header_new(SC, 13, 130000000u, 1);
    m.valid_sim_time_ns = 30000000u;
    m.gps_week = 2394u;
    m.gps_seconds_of_week = 86400.5;
    memcpy(m.r_be_e_m, r_e, sizeof r_e);
    memcpy(m.v_be_e_m_s, v_e, sizeof v_e);
    memcpy(m.r_bn_n_m, r_n, sizeof r_n);
    memcpy(m.v_bn_n_m_s, v_n, sizeof v_n);
    m.flags = FD_GPS_FIX | FD_GPS_ECEF | FD_GPS_INERTIAL;
    check_encoded("GpsMsg", golden, n, enc, fd_encode_gps(&m, enc, sizeof enc));
    e = fd_decode_gps(golden, n, &back);
    CHECK(e.status == FD_OK && same_header(&back.header, &m.header) &&
              back.valid_sim_time_ns == 30000000u && back.gps_week == 2394u &&
              same_bits(&back.gps_seconds_of_week, &m.gps_seconds_of_week, 1) &&
              same_bits(back.r_be_e_m, r_e, 3) && same_bits(back.v_be_e_m_s, v_e, 3) &&
              same_bits(back.r_bn_n_m, r_n, 3) && same_bits(back.v_bn_n_m_s, v_n, 3) &&
              back.flags == 0x07,
          "GpsMsg decodes to the table");
    e = fd_decode_gps(golden, n - 1, &back);
    CHECK(e.status == FD_ERR_LENGTH && e.needed == FD_GPS_LEN, "GpsMsg short");
    CHECK(fd_gps_key(key, sizeof key, "sc1", "gps1") > 0 &&
              strcmp(key, "flexdyn/sc1/tlm/gps/gps1") == 0,
          "GPS key");
    printf("GpsMsg: decode ok\n");
}

/* RelativeStateMsg (protocol 9): the RELATIVE_STATE_GOLDEN table of proto/tests/golden.rs. */
static void test_relative_state(const char *dir) {
    uint8_t golden[256], enc[256];
    size_t n = read_file(dir, "relative_state", golden, sizeof golden);
    fd_relative_state_msg m, back;
    static const double r[3] = {0.5, -100.0, 2.25}, v[3] = {0.125, -0.0, -3.5};
    char key[128];
    fd_error e;
    memset(&m, 0, sizeof m);
    m.header = fd_header_new(SC, 1000u, 10000000000ull, 1000u);
    m.chief_spacecraft_id = 1u;
    m.deputy_spacecraft_id = SC;
    memcpy(m.r_dc_h_m, r, sizeof r);
    memcpy(m.v_dc_h_m_s, v, sizeof v);
    m.range_m = 100.03125;
    m.range_rate_m_s = -0.25;
    check_encoded("RelativeStateMsg", golden, n, enc,
                  fd_encode_relative_state(&m, enc, sizeof enc));
    e = fd_decode_relative_state(golden, n, &back);
    CHECK(e.status == FD_OK && same_header(&back.header, &m.header) &&
              back.chief_spacecraft_id == 1u && back.deputy_spacecraft_id == SC &&
              same_bits(back.r_dc_h_m, r, 3) && same_bits(back.v_dc_h_m_s, v, 3) &&
              same_bits(&back.range_m, &m.range_m, 1) &&
              same_bits(&back.range_rate_m_s, &m.range_rate_m_s, 1),
          "RelativeStateMsg decodes to the table");
    e = fd_decode_relative_state(golden, n - 1, &back);
    CHECK(e.status == FD_ERR_LENGTH && e.needed == FD_RELATIVE_STATE_LEN,
          "RelativeStateMsg short");
    CHECK(fd_relative_state_key(key, sizeof key, "deputy", "chief") > 0 &&
              strcmp(key, "flexdyn/deputy/tlm/rel/chief") == 0,
          "relative state key");
    printf("RelativeStateMsg: decode ok\n");
}

/* FswMsg (protocol 10): the FSW_GOLDEN table of proto/tests/golden.rs. */
static void test_fsw(const char *dir) {
    uint8_t golden[256], enc[256];
    size_t n = read_file(dir, "fsw", golden, sizeof golden);
    static fd_fsw_msg m, back;
    static const double q_est[4] = {0.5, -0.5, 0.5, -0.5}, q_target[4] = {1.0, 0.0, -0.0, 0.0};
    static const double var[3] = {0.25, 0.125, 1.0 / 1048576.0};
    double minus_1_5 = -1.5;
    uint64_t f64_word;
    char key[128];
    fd_error e;
    memcpy(&f64_word, &minus_1_5, 8);
    memset(&m, 0, sizeof m);
    m.header = fd_header_new(SC, 1000u, 10000000000ull, 7u);
    m.flags = FD_FSW_MODE | FD_FSW_ESTIMATE | FD_FSW_TARGET | FD_FSW_COVARIANCE;
    m.mode = 2u;
    memcpy(m.q_est_bn, q_est, sizeof q_est);
    memcpy(m.q_target_rn, q_target, sizeof q_target);
    memcpy(m.att_var_b_rad2, var, sizeof var);
    m.event_count = 2;
    m.events[0] = 3u;
    m.events[1] = 0x0102u;
    m.n_values = 3;
    m.values[0] = f64_word;
    m.values[1] = (uint64_t)(int64_t)-2;
    m.values[2] = 1u;
    CHECK(n == FD_FSW_FIXED_LEN + 3 * 8 && fd_fsw_len(&m) == n, "FswMsg length 172");
    check_encoded("FswMsg", golden, n, enc, fd_encode_fsw(&m, enc, sizeof enc));
    e = fd_decode_fsw(golden, n, &back);
    CHECK(e.status == FD_OK && same_header(&back.header, &m.header) && back.flags == 0x0f &&
              back.mode == 2u && same_bits(back.q_est_bn, q_est, 4) &&
              same_bits(back.q_target_rn, q_target, 4) && same_bits(back.att_var_b_rad2, var, 3) &&
              back.event_count == 2 && back.events[0] == 3u && back.events[1] == 0x0102u &&
              back.n_values == 3 && back.values[0] == 0xBFF8000000000000u &&
              back.values[1] == 0xFFFFFFFFFFFFFFFEu && back.values[2] == 1u,
          "FswMsg decodes to the table");
    e = fd_decode_fsw(golden, n - 1, &back);
    CHECK(e.status == FD_ERR_LENGTH, "FswMsg short");
    golden[123] = 9;
    e = fd_decode_fsw(golden, n, &back);
    CHECK(e.status == FD_ERR_MALFORMED, "FswMsg with nine events is malformed");
    CHECK(fd_fsw_key(key, sizeof key, "sc1", "acs") > 0 && strcmp(key, "flexdyn/sc1/fsw/acs") == 0,
          "fsw key");
    printf("FswMsg: decode ok\n");
}

static void test_keys(void) {
    char key[128];
    CHECK(fd_state_key(key, sizeof key, "sc1") > 0 && strcmp(key, "flexdyn/sc1/tlm/state") == 0,
          "state key");
    CHECK(fd_star_tracker_key(key, sizeof key, "sc1", "st1") > 0 &&
              strcmp(key, "flexdyn/sc1/tlm/st/st1") == 0,
          "star tracker key");
    CHECK(fd_environment_key(key, sizeof key, "sc1") > 0 &&
              strcmp(key, "flexdyn/sc1/tlm/env") == 0,
          "environment key");
    CHECK(fd_magnetometer_key(key, sizeof key, "sc1", "mag1") > 0 &&
              strcmp(key, "flexdyn/sc1/tlm/mag/mag1") == 0,
          "magnetometer key");
    CHECK(fd_css_key(key, sizeof key, "sc1", "css1") > 0 &&
              strcmp(key, "flexdyn/sc1/tlm/css/css1") == 0,
          "coarse sun sensor key");
    CHECK(fd_fss_key(key, sizeof key, "sc1", "fss1") > 0 &&
              strcmp(key, "flexdyn/sc1/tlm/fss/fss1") == 0,
          "fine sun sensor key");
    CHECK(fd_participant_key(key, sizeof key, "sc-1", 4294967295u) > 0 &&
              strcmp(key, "flexdyn/sc-1/participant/4294967295") == 0,
          "participant key");
    CHECK(fd_imu_key(key, sizeof key, "sc1", "a/b") == 0, "a / in a name is rejected");
    CHECK(fd_command_key(key, sizeof key, "sc1", 1u) > 0 && strcmp(key, "flexdyn/sc1/cmd/1") == 0,
          "command key");
    CHECK(fd_command_key(key, sizeof key, "sc1", 0u) > 0 && strcmp(key, "flexdyn/sc1/cmd/0") == 0,
          "command key of sender 0");
    CHECK(fd_command_key(key, 10, "sc1", 1u) == 0, "a key that does not fit is rejected");
    printf("keys: ok\n");
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s <proto/golden directory>\n", argv[0]);
        return 2;
    }
    test_state(argv[1]);
    test_imu_and_star_tracker(argv[1]);
    test_magnetometer(argv[1]);
    test_sun_sensors(argv[1]);
    test_commands(argv[1]);
    test_status(argv[1]);
    test_time(argv[1]);
    test_operator(argv[1]);
    test_environment(argv[1]);
    test_gps(argv[1]);
    test_keys();
    test_faults(argv[1]);
    test_relative_state(argv[1]);
    test_fsw(argv[1]);
    if (failures != 0) {
        fprintf(stderr, "%d check(s) failed\n", failures);
        return 1;
    }
    printf("all C golden checks passed\n");
    return 0;
}
