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
