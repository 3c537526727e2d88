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

