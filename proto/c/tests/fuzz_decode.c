/*
 * Differential-fuzz driver for the C decoders. Reads records from stdin, each a u32 LE length
 * and that many bytes, and writes one line per record and decoder (state, imu, star tracker,
 * magnetometer, css, fss, environment, command, status, time, operator, header, gps, in that order) in the canonical form that proto/tests/c_header.rs
 * also prints from the Rust decoders:
 *
 *   E <reason> [numbers or field]     on a decode error (reason as the Rust DecodeError variant)
 *   O <hex fields...>                 on success: every field in wire order, integers in hex,
 *                                     doubles as their 64-bit patterns in hex
 *   E ReencodeDiffers                 on success, if the C encoder does not give the input
 *                                     bytes back (the Rust side never prints this, so it fails)
 */
#include <stdio.h>
#include <stdlib.h>

#include "flexdyn_proto.h"

static void print_error(const fd_error *e) {
    switch (e->status) {
    case FD_ERR_LENGTH: printf("E Length %zu %zu\n", e->needed, e->actual); break;
    case FD_ERR_TRAILING_BYTES: printf("E TrailingBytes %zu %zu\n", e->needed, e->actual); break;
    case FD_ERR_TOO_LARGE: printf("E TooLarge %zu\n", e->actual); break;
    case FD_ERR_UNKNOWN_VERSION: printf("E UnknownVersion %u\n", (unsigned)e->found_version); break;
    case FD_ERR_NON_FINITE: printf("E NonFinite %s\n", e->field); break;
    case FD_ERR_MALFORMED: printf("E Malformed\n"); break;
    case FD_ERR_CAPACITY: printf("E Capacity\n"); break;
    default: printf("E ?\n"); break;
    }
}

static void f(double d) {
    uint64_t b;
    memcpy(&b, &d, sizeof b);
    printf(" %llx", (unsigned long long)b);
}
static void fs(const double *d, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i) f(d[i]);
}
static void u(uint64_t v) { printf(" %llx", (unsigned long long)v); }
static void h(const fd_header *x) {
    u(x->protocol_version);
    u(x->spacecraft_id);
    u(x->tick);
    u(x->sim_time_ns);
    u(x->seq);
}

static fd_effector_state effectors[FD_MAX_EFFECTORS];
static fd_effector_input inputs[FD_MAX_EFFECTORS];
static uint8_t again[FD_MAX_MESSAGE_BYTES];

/* After a successful decode: the C encoder must give the input bytes back. */
static int reencodes(const uint8_t *buf, size_t len, size_t n) {
    if (n == len && memcmp(again, buf, len) == 0) return 1;
    printf("E ReencodeDiffers\n");
    return 0;
}

static void one(const uint8_t *buf, size_t len) {
    fd_error e;
    {
        fd_state_msg m;
        uint64_t i;
        memset(&m, 0, sizeof m);
        m.effectors = effectors;
        m.effectors_capacity = FD_MAX_EFFECTORS;
        e = fd_decode_state(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_state(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            fs(m.sigma_bn, 3);
            fs(m.q_bn, 4);
            fs(m.omega_bn_b_rad_s, 3);
            fs(m.omega_dot_bn_b_rad_s2, 3);
            fs(m.r_bn_n_m, 3);
            fs(m.v_bn_n_m_s, 3);
            fs(m.nongrav_accel_bn_n_m_s2, 3);
            f(m.orb_energy_j);
            f(m.rot_energy_j);
            fs(m.orb_ang_mom_n, 3);
            fs(m.rot_ang_mom_c_n, 3);
            fs(m.torque_b_nm, 3);
            fs(m.force_b_newton, 3);
            u(m.command_flags);
            u(m.n_effectors);
            for (i = 0; i < m.n_effectors; ++i) {
                u(effectors[i].kind);
                u(effectors[i].flags);
                u(effectors[i].n_states);
                fs(effectors[i].states, (size_t)effectors[i].n_states);
                u(effectors[i].n_outputs);
                fs(effectors[i].outputs, (size_t)effectors[i].n_outputs);
            }
            printf("\n");
        }
    }
    {
        fd_imu_msg m;
        e = fd_decode_imu(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_imu(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            fs(m.omega_p_rad_s, 3);
            fs(m.accel_p_m_s2, 3);
            fs(m.dtheta_p_rad, 3);
            fs(m.dv_p_m_s, 3);
            u(m.saturation_flags);
            printf("\n");
        }
    }
    {
        fd_star_tracker_msg m;
        e = fd_decode_star_tracker(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_star_tracker(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            fs(m.q_cn, 4);
            u(m.valid);
            u(m.status_flags);
            printf("\n");
        }
    }
    {
        fd_magnetometer_msg m;
        e = fd_decode_magnetometer(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_magnetometer(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            fs(m.b_s_t, 3);
            u(m.saturation_flags);
            printf("\n");
        }
    }
    {
        fd_css_msg m;
        e = fd_decode_css(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_css(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            u(m.detector_count);
            fs(m.readings, FD_MAX_CSS_DETECTORS);
            printf("\n");
        }
    }
    {
        fd_fss_msg m;
        e = fd_decode_fss(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_fss(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            fs(&m.alpha_rad, 1);
            fs(&m.beta_rad, 1);
            u(m.flags);
            printf("\n");
        }
    }
    {
        fd_environment_msg m;
        const fd_source_wrench *src[4];
        int i;
        e = fd_decode_environment(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_environment(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            u(m.tai_ns_1958);
            u(m.flags);
            u(m.eclipse);
            fs(m.b_n_t, 3);
            fs(m.b_b_t, 3);
            fs(m.sun_n, 3);
            fs(m.sun_b, 3);
            fs(m.moon_n, 3);
            f(m.shadow_factor);
            f(m.density_kg_m3);
            src[0] = &m.gravity_gradient;
            src[1] = &m.drag;
            src[2] = &m.solar_pressure;
            src[3] = &m.residual_dipole;
            for (i = 0; i < 4; ++i) {
                fs(src[i]->torque_b_nm, 3);
                fs(src[i]->force_b_newton, 3);
            }
            printf("\n");
        }
    }
    {
        fd_command_msg m;
        uint64_t i;
        memset(&m, 0, sizeof m);
        m.inputs = inputs;
        m.inputs_capacity = FD_MAX_EFFECTORS;
        e = fd_decode_command(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_command(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            u(m.sender_id);
            u(m.kind);
            if (m.kind != FD_COMMAND_NO_COMMAND) {
                fs(m.torque_b_nm, 3);
                fs(m.force_b_newton, 3);
            }
            if (m.kind == FD_COMMAND_ACTUATORS) {
                u(m.n_inputs);
                for (i = 0; i < m.n_inputs; ++i) {
                    u(inputs[i].effector_index);
                    u(inputs[i].n_values);
                    fs(inputs[i].values, (size_t)inputs[i].n_values);
                }
            }
            printf("\n");
        }
    }
    {
        fd_status_msg m;
        e = fd_decode_status(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_status(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            u(m.mode);
            u(m.run_state);
            u(m.lateness_p50_ns);
            u(m.lateness_p99_ns);
            u(m.lateness_max_ns);
            u(m.overrun_count);
            u(m.frames_skipped);
            u(m.last_command_tick);
            u(m.command_age_ns);
            u(m.command_stale);
            u(m.stale_policy);
            u(m.rejected_malformed);
            u(m.rejected_bad_version);
            u(m.rejected_non_finite);
            u(m.rejected_wrong_spacecraft);
            u(m.rejected_stale_tick);
            u(m.rejected_unknown_sender);
            u(m.rejected_bad_effector_input);
            u(m.rejected_wrong_identity);
            u(m.rejected_operator_refused);
            u(m.rejected_fault_refused);
            u(m.rejected_fsw_refused);
            u(m.commands_dropped);
            u(m.wall_time_unix_ns);
            u(m.faults_active);
            u(m.faults_active_bits[0]);
            u(m.faults_active_bits[1]);
            u(m.faults_active_bits[2]);
            u(m.faults_active_bits[3]);
            printf("\n");
        }
    }
    {
        fd_time_msg m;
        size_t i;
        e = fd_decode_time(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_time(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            u(m.run_state);
            u(m.mode);
            u(m.flags);
            u(m.frame_ns);
            f(m.speed);
            u(m.tai_ns_1958);
            u(m.utc_year);
            u(m.utc_month);
            u(m.utc_day);
            u(m.utc_hour);
            u(m.utc_minute);
            u(m.utc_second);
            u(m.utc_nanosecond);
            u((uint32_t)m.tai_minus_utc_s);
            u(m.gps_week);
            u(m.gps_ns_of_week);
            u(m.met_ns);
            for (i = 0; i < 8; ++i) u(m.cuc_tai[i]);
            u(m.tone_met.seconds);
            u(m.tone_met.subseconds);
            u(m.tone_tai.seconds);
            u(m.tone_tai.subseconds);
            printf("\n");
        }
    }
    {
        fd_operator_msg m;
        e = fd_decode_operator(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_operator(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            u(m.action);
            u(m.ticks);
            printf("\n");
        }
    }
    {
        fd_header m;
        e = fd_decode_header(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else {
            printf("O");
            h(&m);
            printf("\n");
        }
    }
    {
        fd_gps_msg m; /* the thirteenth decoder (protocol 7) */
        e = fd_decode_gps(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_gps(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            u(m.valid_sim_time_ns);
            u(m.gps_week);
            f(m.gps_seconds_of_week);
            fs(m.r_be_e_m, 3);
            fs(m.v_be_e_m_s, 3);
            fs(m.r_bn_n_m, 3);
            fs(m.v_bn_n_m_s, 3);
            u(m.flags);
            printf("\n");
        }
    }
    {
        fd_fault_event_msg m; /* the fourteenth decoder (protocol 8) */
        size_t i;
        e = fd_decode_fault_event(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_fault_event(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            u(m.fault_index);
            u(m.source);
            u(m.mode);
            u(m.active);
            u(m.edge_ns);
            u(m.axes);
            fs(m.params, 2);
            for (i = 0; i < FD_FAULT_TARGET_LEN; ++i) u(m.target[i]);
            printf("\n");
        }
    }
    {
        fd_fault_command_msg m; /* the fifteenth decoder (protocol 8) */
        size_t i;
        e = fd_decode_fault_command(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_fault_command(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            u(m.action);
            u(m.at_tick);
            u(m.fault_index);
            u(m.mode);
            fs(m.params, 2);
            u(m.axes);
            u(m.duration_ns);
            u(m.seed);
            for (i = 0; i < FD_FAULT_TARGET_LEN; ++i) u(m.target[i]);
            printf("\n");
        }
    }
    {
        fd_relative_state_msg m; /* the sixteenth decoder (protocol 9) */
        e = fd_decode_relative_state(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_relative_state(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            u(m.chief_spacecraft_id);
            u(m.deputy_spacecraft_id);
            fs(m.r_dc_h_m, 3);
            fs(m.v_dc_h_m_s, 3);
            fs(&m.range_m, 1);
            fs(&m.range_rate_m_s, 1);
            printf("\n");
        }
    }
    {
        static fd_fsw_msg m; /* the seventeenth decoder (protocol 10); 2 KiB of values */
        size_t i;
        e = fd_decode_fsw(buf, len, &m);
        if (e.status != FD_OK) {
            print_error(&e);
        } else if (reencodes(buf, len, fd_encode_fsw(&m, again, sizeof again))) {
            printf("O");
            h(&m.header);
            u(m.flags);
            u(m.mode);
            fs(m.q_est_bn, 4);
            fs(m.q_target_rn, 4);
            fs(m.att_var_b_rad2, 3);
            u(m.event_count);
            for (i = 0; i < 8; ++i) u(m.events[i]);
            u(m.n_values);
            for (i = 0; i < m.n_values; ++i) u(m.values[i]);
            printf("\n");
        }
    }
}

int main(void) {
    static uint8_t buf[FD_MAX_MESSAGE_BYTES + 16];
    uint8_t lenb[4];
    while (fread(lenb, 1, 4, stdin) == 4) {
        size_t len = (size_t)fd_get_u32(lenb);
        if (len > sizeof buf || fread(buf, 1, len, stdin) != len) {
            fprintf(stderr, "bad record\n");
            return 2;
        }
        one(buf, len);
    }
    return 0;
}
