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
static inline int32_t fd_get_i32(const uint8_t *p) {
    uint32_t u = fd_get_u32(p); /* two's complement, read without a signed overflow */
    return u <= 0x7FFFFFFFu ? FD_CAST(int32_t, u) : -FD_CAST(int32_t, ~u) - 1;
}
static inline void fd_put_i32(uint8_t *p, int32_t v) {
    fd_put_u32(p, FD_CAST(uint32_t, v));
}
static inline void fd_get_u16s(const uint8_t *p, uint16_t *out, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i) out[i] = fd_get_u16(p + 2 * i);
}
static inline void fd_put_u16s(uint8_t *p, const uint16_t *v, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i) fd_put_u16(p + 2 * i, v[i]);
}
static inline void fd_get_u32s(const uint8_t *p, uint32_t *out, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i) out[i] = fd_get_u32(p + 4 * i);
}
static inline void fd_put_u32s(uint8_t *p, const uint32_t *v, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i) fd_put_u32(p + 4 * i, v[i]);
}
static inline void fd_get_i32s(const uint8_t *p, int32_t *out, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i) out[i] = fd_get_i32(p + 4 * i);
}
static inline void fd_put_i32s(uint8_t *p, const int32_t *v, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i) fd_put_i32(p + 4 * i, v[i]);
}
static inline void fd_get_u64s(const uint8_t *p, uint64_t *out, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i) out[i] = fd_get_u64(p + 8 * i);
}
static inline void fd_put_u64s(uint8_t *p, const uint64_t *v, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i) fd_put_u64(p + 8 * i, v[i]);
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
static inline fd_error fd_walk_values(fd_walker *w, const uint8_t *buf, uint64_t max, size_t size,
                                      const char *what) {
    uint64_t n;
    fd_error e = fd_walk_count(w, buf, max, what, &n);
    if (e.status != FD_OK) return e;
    return fd_walk_skip(w, size * fd_size(n));
}

/* The text rule (README "Decoder rules", step 4): a text field ends at its first NUL byte and
 * every byte after it is NUL. 1 when `p[0..n)` follows it. */
static inline int fd_text_padded(const uint8_t *p, size_t n) {
    size_t i = 0;
    while (i < n && p[i] != 0u) ++i;
    for (; i < n; ++i)
        if (p[i] != 0u) return 0;
    return 1;
}
