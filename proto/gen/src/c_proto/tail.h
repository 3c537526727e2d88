/* The lockstep participant's liveliness token key, flexdyn/<sc>/participant/<sender_id>. */
static inline size_t fd_participant_key(char *out, size_t cap, const char *sc, uint32_t sender_id) {
    char digits[11];
    return fd_key(out, cap, sc, "participant", fd_decimal_u32(digits, sender_id));
}
/* flexdyn/<sc>/fault: the live fault command key, as fd_fault_command_key (its name before the
 * wire table). */
static inline size_t fd_fault_key(char *out, size_t cap, const char *sc) {
    return fd_fault_command_key(out, cap, sc);
}

/* Names from before the wire table, kept for existing code. */
#define FD_STATE_EFFECTOR_COUNT_OFFSET FD_STATE_EFFECTORS_COUNT_OFFSET
#define FD_TIME_CUC_OFFSET FD_TIME_CUC_TAI_OFFSET

#undef FD_CAST
#undef FD_NULL

#endif /* FLEXDYN_PROTO_H */
