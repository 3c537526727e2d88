// lockstep_monitor.cpp - C++17 flight code through libflexdyn_client: a lockstep participant
// that answers every tick with NoCommand, while separate subscriptions to the state, every
// IMU, every star tracker and the status are drained with the poll API (no callbacks, no
// threads of ours). It answers until flexdyn_lockstep_wait returns FLEXDYN_ENDED (the server's
// last status said the run ended and every tick was handed out), checks that the last tick was
// <last_tick> and that its own status subscription saw the same end as flexdyn_run_ended.
//
// Usage: lockstep_monitor <endpoint> <last_tick>
// Prints "states=<n> imus=<n> star_trackers=<n> run_state=<tag>" and exits 0, or prints the
// error and exits 1.
//
// Build (C++17, as strict as flight code is), on one line:
//   g++ -std=c++17 -Wall -Wextra -Werror -pedantic -I proto/c/include -I clients/c/include
//       clients/c/examples/lockstep_monitor.cpp target/release/libflexdyn_client.a
//       -ldl -lgcc_s -lutil -lrt -lpthread -lm -lc -o lockstep_monitor
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "flexdyn_client.h"

namespace {

// The handle, freed on every path.
struct ClientDeleter {
    void operator()(flexdyn_client *c) const { flexdyn_client_free(c); }
};
using Client = std::unique_ptr<flexdyn_client, ClientDeleter>;

struct Counts {
    std::uint64_t states = 0, imus = 0, star_trackers = 0;
};

int fail(const Client &c, const char *what, int rc) {
    std::fprintf(stderr, "lockstep_monitor: %s: %s (code %d)\n", what,
                 flexdyn_last_error(c.get()), rc);
    return 1;
}

// Takes what the separate subscriptions have queued so far.
bool drain(const Client &c, Counts &n, std::vector<fd_effector_state> &effectors) {
    fd_state_msg st{};
    st.effectors = effectors.data();
    st.effectors_capacity = effectors.size();
    int rc;
    while ((rc = flexdyn_poll_state(c.get(), &st)) == FLEXDYN_OK) ++n.states;
    if (rc != FLEXDYN_EMPTY) return false;
    fd_imu_msg imu{};
    std::array<char, FLEXDYN_NAME_CAP> name{};
    while ((rc = flexdyn_poll_imu(c.get(), &imu, name.data(), name.size())) == FLEXDYN_OK)
        ++n.imus;
    if (rc != FLEXDYN_EMPTY) return false;
    fd_star_tracker_msg st_msg{};
    while ((rc = flexdyn_poll_star_tracker(c.get(), &st_msg, nullptr, 0)) == FLEXDYN_OK)
        ++n.star_trackers;
    return rc == FLEXDYN_EMPTY;
}

}  // namespace

int main(int argc, char **argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: %s <endpoint> <last_tick>\n", argv[0]);
        return 2;
    }
    const std::uint64_t last = std::strtoull(argv[2], nullptr, 10);
    Client c(flexdyn_client_new());
    if (!c) return 1;
    const char *connect[] = {argv[1]};
    flexdyn_options opts{};
    opts.connect = connect;
    opts.n_connect = 1;
    int rc = flexdyn_open(c.get(), &opts);
    if (rc != FLEXDYN_OK) return fail(c, "open", rc);
    // Every subscription before the token, so tick 0 is seen by all of them.
    const std::size_t capacity = 8192;
    if ((rc = flexdyn_subscribe_state(c.get(), capacity)) != FLEXDYN_OK ||
        (rc = flexdyn_subscribe_imu(c.get(), nullptr, capacity)) != FLEXDYN_OK ||
        (rc = flexdyn_subscribe_star_tracker(c.get(), nullptr, capacity)) != FLEXDYN_OK ||
        (rc = flexdyn_subscribe_status(c.get(), 64)) != FLEXDYN_OK)
        return fail(c, "subscribe", rc);
    if ((rc = flexdyn_lockstep_join(c.get(), 1, 30000)) != FLEXDYN_OK)
        return fail(c, "join", rc);

    std::vector<fd_effector_state> effectors(FD_MAX_EFFECTORS);
    fd_state_msg tick{};
    tick.effectors = effectors.data();
    tick.effectors_capacity = effectors.size();
    Counts n;
    std::uint64_t answered = 0, last_seen = 0;
    while ((rc = flexdyn_lockstep_wait(c.get(), &tick, 5000)) == FLEXDYN_OK) {
        last_seen = tick.header.tick;
        if ((rc = flexdyn_lockstep_answer_no_command(c.get())) != FLEXDYN_OK)
            return fail(c, "answer", rc);
        ++answered;
        if (!drain(c, n, effectors)) return fail(c, "poll", -1);
    }
    if (rc != FLEXDYN_ENDED) return fail(c, "wait", rc);
    // The run is over: how it ended, and the same from the status subscription (its last one).
    std::int32_t ended_state = 0;
    std::uint64_t ended_tick = 0;
    if (flexdyn_run_ended(c.get(), &ended_state, &ended_tick) != 1)
        return fail(c, "FLEXDYN_ENDED without an end of run", rc);
    if (answered != last + 1 || last_seen != last || ended_tick != last) {
        std::fprintf(stderr, "lockstep_monitor: %llu ticks up to %llu, the run ended at %llu\n",
                     static_cast<unsigned long long>(answered),
                     static_cast<unsigned long long>(last_seen),
                     static_cast<unsigned long long>(ended_tick));
        return 1;
    }
    fd_status_msg status{};
    std::uint32_t run_state = FD_RUN_STATE_RUNNING;
    while ((rc = flexdyn_poll_status(c.get(), &status)) == FLEXDYN_OK) run_state = status.run_state;
    if (rc != FLEXDYN_EMPTY) return fail(c, "status", rc);
    if (run_state != static_cast<std::uint32_t>(ended_state)) {
        std::fprintf(stderr, "lockstep_monitor: the last status says %u, flexdyn_run_ended %d\n",
                     run_state, static_cast<int>(ended_state));
        return 1;
    }
    if (!drain(c, n, effectors)) return fail(c, "poll", -1);
    if ((rc = flexdyn_close(c.get())) != FLEXDYN_OK) return fail(c, "close", rc);
    std::printf("states=%llu imus=%llu star_trackers=%llu run_state=%u\n",
                static_cast<unsigned long long>(n.states),
                static_cast<unsigned long long>(n.imus),
                static_cast<unsigned long long>(n.star_trackers), run_state);
    return 0;
}
