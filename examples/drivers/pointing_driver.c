/*
 * A pointing loop written as flight drivers are written: it opens serial lines with open(2)
 * and termios, reads a rate sensor's COBS frames, asks a star tracker for its quaternion in
 * sync-and-length frames, commands four reaction wheel drives in SLIP frames and reads their
 * speed reports, and (optionally) parses a GPS receiver's NMEA 0183 sentences line by line and
 * takes a magnetometer's CCSDS Space Packets from UDP. It includes no flexdyn header and links
 * no flexdyn library: the wire formats are those of the device descriptions' comments
 * (the files under scenarios/devices/), which it follows as a driver follows a vendor's ICD.
 *
 * Against flexdyn's device gateway (book: "Device gateway") it flies
 * scenarios/wheels_star_tracker.toml (or gateway_pointing.toml, which adds the GPS and the
 * magnetometer) in lockstep:
 *
 *   flexdyn run --mode lockstep --participants 1 --config scenarios/wheels_star_tracker.toml &
 *   flexdyn gateway --devices scenarios/wheels_star_tracker.devices.toml --link-dir /tmp &
 *   cc -std=c99 -O2 -o pointing_driver examples/drivers/pointing_driver.c -lm
 *   ./pointing_driver /tmp
 *
 * Usage: pointing_driver DIR [--gps] [--mag-udp PORT] [--hostile] [--k K] [--p P]
 *   DIR          where the device links are: st1.tty, imu.tty, rw1.tty .. rw4.tty (gps1.tty)
 *   --gps        also read DIR/gps1.tty (NMEA 0183 GGA, RMC, ZDA) and check each sentence
 *   --mag-udp N  also take the magnetometer's packets on UDP 127.0.0.1:N
 *   --hostile    before each command, also write malformed frames of every kind the gateway
 *                must count and never apply (bad CRC, bad length, oversize, garbage, partial
 *                frames, a flood); their tally is printed at the end
 *   --k, --p     the PD gains: torque = -K sigma_BN - P omega (N m, N m s)
 *
 * Each 0.1 s cycle (paced by the rate sensor's 10 Hz frames):
 *   1. read one RATE frame (omega in the sensor frame, here B);
 *   2. send QUATERNION_REQUEST, read QUATERNION (q_CN, scalar first);
 *   3. sigma_BN from [BN] = [CB]^T [CN] with the tracker's mounting [CB];
 *   4. L = -K sigma - P omega, then the wheel motor torques u = -G^+ L (the hub receives
 *      -sum g_j u_j; G = [g_1 .. g_4], G^+ = G^T (G G^T)^-1);
 *   5. per wheel: TORQUE_COMMAND, then SPEED_REQUEST, read SPEED_REPORT.
 * It ends, exit 0, when the lines close (the gateway left at the end of the run), printing
 * "cycles=N sigma=... omega=... gga=... rmc=... zda=... nmea_bad=... mag=... mag_bad=..."
 * and, with --hostile, "hostile bad_crc=... bad_length=... oversize=... garbage_bytes=...
 * partial=... flood_bytes=...".
 */
#define _DEFAULT_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#define N_WHEELS 4
#define LINE_TIMEOUT_MS 20000

/* ---- checksums (each by its published parameters; check values in the comments) ---- */

/* CRC-16/CCITT-FALSE: poly 0x1021, init 0xFFFF, not reflected, xorout 0 (check 0x29B1). */
static uint16_t crc16_ccitt_false(const uint8_t *p, size_t n) {
    uint16_t crc = 0xFFFF;
    for (size_t i = 0; i < n; i++) {
        crc ^= (uint16_t)(p[i] << 8);
        for (int b = 0; b < 8; b++)
            crc = (crc & 0x8000) ? (uint16_t)((crc << 1) ^ 0x1021) : (uint16_t)(crc << 1);
    }
    return crc;
}

/* CRC-16/KERMIT: poly 0x1021 reflected (0x8408), init 0, xorout 0 (check 0x2189). */
static uint16_t crc16_kermit(const uint8_t *p, size_t n) {
    uint16_t crc = 0;
    for (size_t i = 0; i < n; i++) {
        crc ^= p[i];
        for (int b = 0; b < 8; b++)
            crc = (crc & 1) ? (uint16_t)((crc >> 1) ^ 0x8408) : (uint16_t)(crc >> 1);
    }
    return crc;
}

/* CRC-32/ISO-HDLC: poly 0x04C11DB7 reflected (0xEDB88320), init and xorout 0xFFFFFFFF
 * (check 0xCBF43926). */
static uint32_t crc32_iso_hdlc(const uint8_t *p, size_t n) {
    uint32_t crc = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        crc ^= p[i];
        for (int b = 0; b < 8; b++)
            crc = (crc & 1) ? (crc >> 1) ^ 0xEDB88320u : crc >> 1;
    }
    return crc ^ 0xFFFFFFFFu;
}

/* ---- serial lines ---- */

static int open_line(const char *dir, const char *name, speed_t speed) {
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    int fd = open(path, O_RDWR | O_NOCTTY);
    if (fd < 0) {
        fprintf(stderr, "pointing_driver: cannot open %s: %s\n", path, strerror(errno));
        exit(2);
    }
    struct termios t;
    if (tcgetattr(fd, &t) != 0) {
        fprintf(stderr, "pointing_driver: %s is not a terminal: %s\n", path, strerror(errno));
        exit(2);
    }
    cfmakeraw(&t);
    cfsetispeed(&t, speed);
    cfsetospeed(&t, speed);
    t.c_cc[VMIN] = 1;
    t.c_cc[VTIME] = 0;
    if (tcsetattr(fd, TCSANOW, &t) != 0) {
        fprintf(stderr, "pointing_driver: tcsetattr %s: %s\n", path, strerror(errno));
        exit(2);
    }
    return fd;
}

/* One byte from fd, waiting up to LINE_TIMEOUT_MS; -1 when the line closed or went quiet. */
static int read_byte(int fd) {
    struct pollfd p = {fd, POLLIN, 0};
    int r = poll(&p, 1, LINE_TIMEOUT_MS);
    if (r <= 0) return -1;
    uint8_t b;
    ssize_t n = read(fd, &b, 1);
    return n == 1 ? b : -1;
}

static int write_all(int fd, const uint8_t *p, size_t n) {
    while (n > 0) {
        ssize_t w = write(fd, p, n);
        if (w < 0) {
            if (errno == EINTR) continue;
            return -1;
        }
        p += w;
        n -= (size_t)w;
    }
    return 0;
}

/* ---- star tracker: sync 0xEB 0x90, LEN (payload octets), payload, CRC-16/CCITT-FALSE BE ---- */

static size_t st_frame(const uint8_t *payload, uint8_t len, uint8_t *out) {
    out[0] = 0xEB;
    out[1] = 0x90;
    out[2] = len;
    memcpy(out + 3, payload, len);
    uint16_t crc = crc16_ccitt_false(out, 3u + len);
    out[3 + len] = (uint8_t)(crc >> 8);
    out[4 + len] = (uint8_t)(crc & 0xFF);
    return 5u + len;
}

/* Reads one valid frame's payload into p (resynchronising on bad ones); its length. */
static int st_read(int fd, uint8_t *p) {
    for (;;) {
        int b = read_byte(fd);
        if (b < 0) return -1;
        if (b != 0xEB) continue;
        if ((b = read_byte(fd)) < 0) return -1;
        if (b != 0x90) continue;
        int len = read_byte(fd);
        if (len < 0) return -1;
        uint8_t f[3 + 255 + 2] = {0xEB, 0x90, (uint8_t)len};
        for (int i = 0; i < len + 2; i++) {
            if ((b = read_byte(fd)) < 0) return -1;
            f[3 + i] = (uint8_t)b;
        }
        uint16_t crc = (uint16_t)(f[3 + len] << 8 | f[4 + len]);
        if (crc != crc16_ccitt_false(f, 3u + (unsigned)len)) continue;
        memcpy(p, f + 3, (size_t)len);
        return len;
    }
}

static int32_t be_i32(const uint8_t *p) {
    return (int32_t)((uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3]);
}

/* ---- wheels: SLIP (END 0xC0, ESC 0xDB), content = payload + CRC-16/KERMIT LE ---- */

static size_t slip_frame(const uint8_t *payload, size_t len, uint8_t *out) {
    uint8_t content[64];
    memcpy(content, payload, len);
    uint16_t crc = crc16_kermit(payload, len);
    content[len] = (uint8_t)(crc & 0xFF);
    content[len + 1] = (uint8_t)(crc >> 8);
    size_t n = 0;
    out[n++] = 0xC0;
    for (size_t i = 0; i < len + 2; i++) {
        if (content[i] == 0xC0) {
            out[n++] = 0xDB;
            out[n++] = 0xDC;
        } else if (content[i] == 0xDB) {
            out[n++] = 0xDB;
            out[n++] = 0xDD;
        } else {
            out[n++] = content[i];
        }
    }
    out[n++] = 0xC0;
    return n;
}

/* Reads one valid SLIP frame's payload (check removed); its length. A frame with a bad escape
 * or longer than the buffer is dropped whole. */
static int slip_read(int fd, uint8_t *p, size_t cap) {
    uint8_t c[128];
    size_t n = 0;
    int esc = 0, bad = 0;
    for (;;) {
        int b = read_byte(fd);
        if (b < 0) return -1;
        if (b == 0xC0) {
            if (n >= 3 && !esc && !bad) {
                uint16_t crc = (uint16_t)(c[n - 2] | c[n - 1] << 8);
                if (crc == crc16_kermit(c, n - 2) && n - 2 <= cap) {
                    memcpy(p, c, n - 2);
                    return (int)(n - 2);
                }
            }
            n = 0;
            esc = 0;
            bad = 0;
            continue;
        }
        if (esc) {
            esc = 0;
            if (b == 0xDC) b = 0xC0;
            else if (b == 0xDD) b = 0xDB;
            else {
                bad = 1;
                continue;
            }
        } else if (b == 0xDB) {
            esc = 1;
            continue;
        }
        if (n < sizeof c) c[n++] = (uint8_t)b;
        else bad = 1;
    }
}

/* ---- rate sensor: COBS frames delimited by 0x00; content = payload + CRC-32 LE ---- */

static int cobs_read(int fd, uint8_t *p, size_t cap) {
    uint8_t e[256];
    for (;;) {
        size_t n = 0;
        int b;
        while ((b = read_byte(fd)) > 0)
            if (n < sizeof e) e[n++] = (uint8_t)b;
        if (b < 0) return -1;
        /* Decode: each code octet k is followed by k-1 data octets, then an implied zero
         * unless k is 0xFF or the block ends the frame. */
        uint8_t d[256];
        size_t m = 0, i = 0;
        int ok = n > 0;
        while (ok && i < n) {
            uint8_t code = e[i++];
            if (code == 0 || i + code - 1u > n) {
                ok = 0;
                break;
            }
            for (uint8_t k = 1; k < code; k++) d[m++] = e[i++];
            if (code != 0xFF && i < n) d[m++] = 0;
        }
        if (!ok || m < 5 || m - 4 > cap) continue;
        uint32_t crc = (uint32_t)d[m - 4] | (uint32_t)d[m - 3] << 8 | (uint32_t)d[m - 2] << 16 |
                       (uint32_t)d[m - 1] << 24;
        if (crc != crc32_iso_hdlc(d, m - 4)) continue;
        memcpy(p, d, m - 4);
        return (int)(m - 4);
    }
}

static int32_t le_i32(const uint8_t *p) {
    return (int32_t)((uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
                     (uint32_t)p[3] << 24);
}

static float le_f32(const uint8_t *p) {
    uint32_t u = (uint32_t)le_i32(p);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* ---- NMEA 0183: "$<body>*<hh>\r\n", hh the XOR of the body's characters ---- */

struct nmea {
    int fd;
    char line[128];
    size_t n;
    long gga, rmc, zda, bad;
    double lat_deg, lon_deg, alt_m;
};

static void nmea_line(struct nmea *g) {
    char *s = g->line;
    size_t n = g->n;
    if (n > 0 && s[n - 1] == '\r') s[--n] = 0;
    char *star = strrchr(s, '*');
    if (s[0] != '$' || !star || star + 3 != s + n) {
        g->bad++;
        return;
    }
    unsigned x = 0;
    for (char *c = s + 1; c < star; c++) x ^= (unsigned char)*c;
    if ((unsigned)strtoul(star + 1, NULL, 16) != x) {
        g->bad++;
        return;
    }
    if (strncmp(s + 3, "GGA,", 4) == 0) {
        /* $GPGGA,hhmmss.ss,llll.ll,a,yyyyy.yy,a,q,nn,h.h,alt,M,... */
        char *f[16] = {0};
        int k = 0;
        for (char *c = s; c < star && k < 16; c++)
            if (*c == ',') f[k++] = c + 1;
        if (k >= 9 && f[1][0] && f[3][0]) {
            double lat = atof(f[1]), lon = atof(f[3]);
            g->lat_deg = floor(lat / 100) + fmod(lat, 100) / 60;
            g->lon_deg = floor(lon / 100) + fmod(lon, 100) / 60;
            if (f[2][0] == 'S') g->lat_deg = -g->lat_deg;
            if (f[4][0] == 'W') g->lon_deg = -g->lon_deg;
            g->alt_m = atof(f[8]);
        }
        g->gga++;
    } else if (strncmp(s + 3, "RMC,", 4) == 0) {
        g->rmc++;
    } else if (strncmp(s + 3, "ZDA,", 4) == 0) {
        g->zda++;
    } else {
        g->bad++;
    }
}

/* Takes whatever the receiver sent (non-blocking), a line at a time. */
static void nmea_poll(struct nmea *g) {
    char buf[512];
    ssize_t r;
    while ((r = read(g->fd, buf, sizeof buf)) > 0) {
        for (ssize_t i = 0; i < r; i++) {
            if (buf[i] == '\n') {
                g->line[g->n] = 0;
                nmea_line(g);
                g->n = 0;
            } else if (g->n + 1 < sizeof g->line) {
                g->line[g->n++] = buf[i];
            } else {
                g->n = 0;
                g->bad++;
            }
        }
    }
}

/* ---- magnetometer: CCSDS Space Packets, APID 0x120, CUC 4+2, 3 x i32 (0.1 nT), CRC ---- */

struct mag {
    int fd;
    long packets, bad;
    int last_seq;
    double b_nt[3];
};

static void mag_poll(struct mag *m) {
    uint8_t p[256];
    ssize_t r;
    while ((r = recv(m->fd, p, sizeof p, MSG_DONTWAIT)) > 0) {
        /* primary header: version 0, type 0, sec. header 1, APID; data length = 20 */
        unsigned apid = (unsigned)(p[0] & 0x07) << 8 | p[1];
        unsigned len = (unsigned)p[4] << 8 | p[5];
        uint16_t crc = r >= 27 ? (uint16_t)(p[25] << 8 | p[26]) : 0;
        if (r != 27 || (p[0] >> 5) != 0 || !(p[0] & 0x08) || apid != 0x120 || len != 20 ||
            crc != crc16_ccitt_false(p, 25)) {
            m->bad++;
            continue;
        }
        int seq = (p[2] & 0x3F) << 8 | p[3];
        if (m->last_seq >= 0 && seq != ((m->last_seq + 1) & 0x3FFF)) m->bad++;
        m->last_seq = seq;
        for (int i = 0; i < 3; i++) m->b_nt[i] = 0.1 * be_i32(p + 12 + 4 * i);
        m->packets++;
    }
}

/* ---- attitude ---- */

/* [CN] from q_CN (scalar first), Schaub & Junkins eq. (3.95). */
static void dcm_from_q(const double q[4], double c[3][3]) {
    double b0 = q[0], b1 = q[1], b2 = q[2], b3 = q[3];
    c[0][0] = b0 * b0 + b1 * b1 - b2 * b2 - b3 * b3;
    c[0][1] = 2 * (b1 * b2 + b0 * b3);
    c[0][2] = 2 * (b1 * b3 - b0 * b2);
    c[1][0] = 2 * (b1 * b2 - b0 * b3);
    c[1][1] = b0 * b0 - b1 * b1 + b2 * b2 - b3 * b3;
    c[1][2] = 2 * (b2 * b3 + b0 * b1);
    c[2][0] = 2 * (b1 * b3 + b0 * b2);
    c[2][1] = 2 * (b2 * b3 - b0 * b1);
    c[2][2] = b0 * b0 - b1 * b1 - b2 * b2 + b3 * b3;
}

/* The short-rotation MRPs of a DCM, through Sheppard's method for the quaternion. */
static void mrp_from_dcm(double c[3][3], double s[3]) {
    double tr = c[0][0] + c[1][1] + c[2][2];
    double b2[4] = {(1 + tr) / 4, (1 + 2 * c[0][0] - tr) / 4, (1 + 2 * c[1][1] - tr) / 4,
                    (1 + 2 * c[2][2] - tr) / 4};
    int k = 0;
    for (int i = 1; i < 4; i++)
        if (b2[i] > b2[k]) k = i;
    double b[4];
    b[k] = sqrt(b2[k]);
    double d = 4 * b[k];
    switch (k) {
    case 0:
        b[1] = (c[1][2] - c[2][1]) / d;
        b[2] = (c[2][0] - c[0][2]) / d;
        b[3] = (c[0][1] - c[1][0]) / d;
        break;
    case 1:
        b[0] = (c[1][2] - c[2][1]) / d;
        b[2] = (c[0][1] + c[1][0]) / d;
        b[3] = (c[2][0] + c[0][2]) / d;
        break;
    case 2:
        b[0] = (c[2][0] - c[0][2]) / d;
        b[1] = (c[0][1] + c[1][0]) / d;
        b[3] = (c[1][2] + c[2][1]) / d;
        break;
    default:
        b[0] = (c[0][1] - c[1][0]) / d;
        b[1] = (c[2][0] + c[0][2]) / d;
        b[2] = (c[1][2] + c[2][1]) / d;
        break;
    }
    if (b[0] < 0)
        for (int i = 0; i < 4; i++) b[i] = -b[i];
    for (int i = 0; i < 3; i++) s[i] = b[i + 1] / (1 + b[0]);
}

/* ---- hostile input: what the gateway must count and never apply ---- */

struct hostile {
    int on;
    unsigned long rng;
    long calls;
    long bad_crc, bad_length, oversize, garbage_bytes, partial, flood_bytes;
};

static uint8_t next_byte(struct hostile *h, uint8_t avoid1, uint8_t avoid2) {
    for (;;) {
        h->rng = h->rng * 6364136223846793005ul + 1442695040888963407ul;
        uint8_t b = (uint8_t)(h->rng >> 56);
        if (b != avoid1 && b != avoid2) return b;
    }
}

/* Malformed star-tracker input, each kind once per call, every byte of it counted by the
 * gateway's sync-and-length decoder as described in the tally below. */
static void hostile_tracker(int fd, struct hostile *h) {
    uint8_t f[4096];
    /* every 50th cycle, a flood: 4096 octets, none of them the first sync octet */
    if (h->calls++ % 50 == 0) {
        for (size_t i = 0; i < sizeof f; i++) f[i] = next_byte(h, 0xEB, 0xEB);
        write_all(fd, f, sizeof f);
        h->flood_bytes += (long)sizeof f;
    }
    /* garbage: 7 octets, none of them the first sync octet */
    for (int i = 0; i < 7; i++) f[i] = next_byte(h, 0xEB, 0xEB);
    write_all(fd, f, 7);
    h->garbage_bytes += 7;
    /* a request with its CRC's last octet flipped */
    uint8_t req[1] = {0x01};
    size_t n = st_frame(req, 1, f);
    f[n - 1] ^= 0x5A;
    write_all(fd, f, n);
    h->bad_crc++;
    /* a length of 0 (no id): too short for any message */
    n = st_frame(req, 0, f);
    write_all(fd, f, n);
    h->bad_length++;
}

/* Malformed wheel input: a frame with a bad CRC and a frame whose payload is too short for
 * its message; the SLIP decoder counts them, the engine never applies them. */
static void hostile_wheel(int fd, struct hostile *h) {
    uint8_t f[600];
    /* a frame cut short: END, the id and one octet, and no END (the next frame's opening END
     * closes it) */
    const uint8_t cut[3] = {0xC0, 0x10, 0xE8};
    write_all(fd, cut, sizeof cut);
    h->partial++;
    uint8_t cmd[3] = {0x10, 0x10, 0x27}; /* +100 mN m */
    size_t n = slip_frame(cmd, 3, f);
    f[n - 2] ^= 0x01; /* the CRC's high octet (never an escape or END after the flip) */
    write_all(fd, f, n);
    h->bad_crc++;
    uint8_t shortcmd[2] = {0x10, 0x10};
    n = slip_frame(shortcmd, 2, f);
    write_all(fd, f, n);
    h->bad_length++;
    /* 300 non-END octets in one frame: longer than any frame the device takes */
    f[0] = 0xC0;
    for (int i = 1; i <= 300; i++) f[i] = next_byte(h, 0xC0, 0xDB);
    write_all(fd, f, 301);
    h->oversize++;
}

/* ---- the loop ---- */

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr,
                "usage: pointing_driver DIR [--gps] [--mag-udp PORT] [--hostile] [--k K] "
                "[--p P]\n");
        return 2;
    }
    const char *dir = argv[1];
    int gps_on = 0, mag_port = 0;
    double k_nm = 10.0, p_nms = 150.0;
    struct hostile h = {0, 0x853c49e6748fea9bul, 0, 0, 0, 0, 0, 0, 0};
    for (int i = 2; i < argc; i++) {
        if (strcmp(argv[i], "--gps") == 0) gps_on = 1;
        else if (strcmp(argv[i], "--hostile") == 0) h.on = 1;
        else if (strcmp(argv[i], "--mag-udp") == 0 && i + 1 < argc) mag_port = atoi(argv[++i]);
        else if (strcmp(argv[i], "--k") == 0 && i + 1 < argc) k_nm = atof(argv[++i]);
        else if (strcmp(argv[i], "--p") == 0 && i + 1 < argc) p_nms = atof(argv[++i]);
        else {
            fprintf(stderr, "pointing_driver: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    int st = open_line(dir, "st1.tty", B115200);
    int imu = open_line(dir, "imu.tty", B460800);
    int rw[N_WHEELS];
    for (int j = 0; j < N_WHEELS; j++) {
        char name[16];
        snprintf(name, sizeof name, "rw%d.tty", j + 1);
        rw[j] = open_line(dir, name, B460800);
    }
    struct nmea g = {-1, {0}, 0, 0, 0, 0, 0, 0, 0, 0};
    if (gps_on) {
        g.fd = open_line(dir, "gps1.tty", B9600);
        fcntl(g.fd, F_SETFL, fcntl(g.fd, F_GETFL) | O_NONBLOCK);
    }
    struct mag m = {-1, 0, 0, -1, {0, 0, 0}};
    if (mag_port) {
        m.fd = socket(AF_INET, SOCK_DGRAM, 0);
        struct sockaddr_in a = {0};
        a.sin_family = AF_INET;
        a.sin_port = htons((uint16_t)mag_port);
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        if (m.fd < 0 || bind(m.fd, (struct sockaddr *)&a, sizeof a) != 0) {
            fprintf(stderr, "pointing_driver: cannot bind UDP %d: %s\n", mag_port,
                    strerror(errno));
            return 2;
        }
    }

    /* The mounting: the tracker's [CB] (C x = B x, C y = B z, C z = -B y), the wheels' spin
     * axes in B (30 deg above the x-y plane at azimuths 45, 135, 225, 315 deg). */
    const double cb[3][3] = {{1, 0, 0}, {0, 0, 1}, {0, -1, 0}};
    const double ca = cos(30 * M_PI / 180), sa = sin(30 * M_PI / 180);
    double g_b[N_WHEELS][3];
    for (int j = 0; j < N_WHEELS; j++) {
        double az = (45 + 90 * j) * M_PI / 180;
        g_b[j][0] = ca * cos(az);
        g_b[j][1] = ca * sin(az);
        g_b[j][2] = sa;
    }
    /* G^+ = G^T (G G^T)^-1, with (G G^T)^-1 by cofactors. */
    double a[3][3] = {{0}}, ai[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            for (int j = 0; j < N_WHEELS; j++) a[r][c] += g_b[j][r] * g_b[j][c];
    double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                 a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                 a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
            ai[r][c] = (a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1]) / det;
        }

    long cycles = 0;
    double sigma[3] = {0, 0, 0}, omega[3] = {0, 0, 0}, speed_rpm[N_WHEELS] = {0};
    for (;;) {
        uint8_t p[300];
        /* 1. the rate sensor's frame paces the cycle */
        int n = cobs_read(imu, p, sizeof p);
        if (n < 0) {
            fprintf(stderr, "pointing_driver: the rate sensor's line closed (or was silent for 20 s): done\n");
            break;
        }
        if (n != 20 || p[0] != 0x31) continue;
        for (int i = 0; i < 3; i++) omega[i] = 1e-8 * le_i32(p + 1 + 4 * i);

        /* 2. the tracker's quaternion */
        if (h.on) hostile_tracker(st, &h);
        uint8_t f[64], req[1] = {0x01};
        size_t fl = st_frame(req, 1, f);
        if (write_all(st, f, fl) != 0) break;
        n = st_read(st, p);
        if (n < 0) {
            fprintf(stderr, "pointing_driver: no answer from the star tracker\n");
            break;
        }
        int valid = 0;
        double q[4];
        if (n == 28 && p[0] == 0x81) {
            for (int i = 0; i < 4; i++) q[i] = be_i32(p + 1 + 4 * i) / 1073741824.0;
            valid = p[17] == 1;
        }

        /* 3.-4. the control law and the wheel torques */
        double u[N_WHEELS] = {0};
        if (valid) {
            double cn[3][3], bn[3][3];
            dcm_from_q(q, cn);
            for (int r = 0; r < 3; r++)
                for (int c = 0; c < 3; c++) {
                    bn[r][c] = 0;
                    for (int k = 0; k < 3; k++) bn[r][c] += cb[k][r] * cn[k][c];
                }
            mrp_from_dcm(bn, sigma);
            double l[3], y[3];
            for (int i = 0; i < 3; i++) l[i] = -k_nm * sigma[i] - p_nms * omega[i];
            for (int r = 0; r < 3; r++) y[r] = ai[r][0] * l[0] + ai[r][1] * l[1] + ai[r][2] * l[2];
            for (int j = 0; j < N_WHEELS; j++)
                u[j] = -(g_b[j][0] * y[0] + g_b[j][1] * y[1] + g_b[j][2] * y[2]);
        }

        /* 5. the wheel drives: torque (units of 0.01 mN m, +-200 mN m), then the speed */
        for (int j = 0; j < N_WHEELS; j++) {
            if (h.on) hostile_wheel(rw[j], &h);
            double raw = u[j] * 1e5;
            raw = raw > 20000 ? 20000 : raw < -20000 ? -20000 : raw;
            int16_t t = (int16_t)lrint(raw);
            uint8_t cmd[3] = {0x10, (uint8_t)((uint16_t)t & 0xFF), (uint8_t)((uint16_t)t >> 8)};
            uint8_t sf[16], sreq[1] = {0x20};
            fl = slip_frame(cmd, 3, f);
            size_t fl2 = slip_frame(sreq, 1, sf);
            if (write_all(rw[j], f, fl) != 0 || write_all(rw[j], sf, fl2) != 0) goto end;
            n = slip_read(rw[j], p, sizeof p);
            if (n < 0) {
                fprintf(stderr, "pointing_driver: no speed report from wheel %d\n", j + 1);
                goto end;
            }
            if (n == 7 && p[0] == 0xA0) speed_rpm[j] = le_f32(p + 1);
        }
        if (gps_on) nmea_poll(&g);
        if (mag_port) mag_poll(&m);
        cycles++;
        if (cycles % 100 == 0)
            printf("cycle %ld sigma=%.6e omega=%.6e rw1_rpm=%.1f\n", cycles,
                   sqrt(sigma[0] * sigma[0] + sigma[1] * sigma[1] + sigma[2] * sigma[2]),
                   sqrt(omega[0] * omega[0] + omega[1] * omega[1] + omega[2] * omega[2]),
                   speed_rpm[0]);
    }
end:
    if (gps_on) nmea_poll(&g);
    if (mag_port) mag_poll(&m);
    printf("cycles=%ld sigma=%.6e omega=%.6e gga=%ld rmc=%ld zda=%ld nmea_bad=%ld lat=%.6f "
           "lon=%.6f alt=%.1f mag=%ld mag_bad=%ld\n",
           cycles, sqrt(sigma[0] * sigma[0] + sigma[1] * sigma[1] + sigma[2] * sigma[2]),
           sqrt(omega[0] * omega[0] + omega[1] * omega[1] + omega[2] * omega[2]), g.gga, g.rmc,
           g.zda, g.bad, g.lat_deg, g.lon_deg, g.alt_m, m.packets, m.bad);
    if (h.on)
        printf("hostile bad_crc=%ld bad_length=%ld oversize=%ld garbage_bytes=%ld partial=%ld "
               "flood_bytes=%ld\n",
               h.bad_crc, h.bad_length, h.oversize, h.garbage_bytes, h.partial, h.flood_bytes);
    return 0;
}
