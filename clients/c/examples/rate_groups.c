/*
 * rate_groups.c - a flight-software rate-group driver run off the simulation's ticks
 * (flexdyn_wait_tick on flexdyn/<sc>/tlm/time), not off the wall clock: it runs 1 Hz, 10 Hz and
 * 100 Hz groups from the tick count, so it follows the server's speed (--speed) and stops when
 * the server is paused (NOS3 #521, #590).
 *
 * Each group's period in ticks comes from the time message's frame_ns (nobody repeats the step
 * by hand): group g runs on tick k when k is a multiple of 1 s / (rate_g * frame_ns). Counting
 * starts at the first tick that is a multiple of the slowest group's period, so K ticks run
 * the 1 Hz group K / periods exactly.
 *
 * Usage: rate_groups <endpoint> <ticks K> [pause_after P]
 *   With P, the driver asks the server (flexdyn_send_operator) to pause after its P-th tick,
 *   notes every 300 ms without a tick while the server says Paused ("held ..." lines, with the
 *   groups' counts: they do not move), and resumes it after three such stalls.
 * Prints "done 1Hz=<n> 10Hz=<n> 100Hz=<n> ticks=<K> stalls=<n> held_at=<tick>" and exits 0.
 * If the server ends the run first, flexdyn_wait_tick returns FLEXDYN_ENDED once every tick
 * received is taken: the driver prints "run ended: <finished|stopped|failed> at tick <n>", then
 * the done line with the ticks it counted, and exits 0 (1 if the run failed). A gap in the
 * ticks, a stall of a running server, or any error exits 1.
 *
 * Build (C99), on one line:
 *   cc -std=c99 -Wall -Wextra -Werror -pedantic -I proto/c/include -I clients/c/include
 *       clients/c/examples/rate_groups.c target/release/libflexdyn_client.a
 *       -ldl -lgcc_s -lutil -lrt -lpthread -lm -lc -o rate_groups
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "flexdyn_client.h"

#define N_GROUPS 3
static const double rate_hz[N_GROUPS] = {1.0, 10.0, 100.0};
static const char *const names[N_GROUPS] = {"1Hz", "10Hz", "100Hz"};

static int fail(flexdyn_client *c, const char *what, int rc) {
    fprintf(stderr, "rate_groups: %s: %s (code %d)\n", what, flexdyn_last_error(c), rc);
    flexdyn_client_free(c);
    return 1;
}

int main(int argc, char **argv) {
    flexdyn_client *c;
    flexdyn_options opts;
    fd_time_msg t, now;
    uint64_t period[N_GROUPS], count[N_GROUPS] = {0, 0, 0};
    uint64_t ticks, pause_after = 0, done = 0, prev = 0, held_at = 0;
    int rc, g, started = 0, stalls = 0, pause_sent = 0, failed = 0;
    if (argc < 3) {
        fprintf(stderr, "usage: rate_groups <endpoint> <ticks> [pause_after]\n");
        return 2;
    }
    ticks = strtoull(argv[2], NULL, 10);
    if (argc > 3) pause_after = strtoull(argv[3], NULL, 10);
    if ((c = flexdyn_client_new()) == NULL) return 1;
    memset(&opts, 0, sizeof opts);
    opts.connect = (const char *const *)&argv[1];
    opts.n_connect = 1;
    if ((rc = flexdyn_open(c, &opts)) != FLEXDYN_OK) return fail(c, "open", rc);
    if ((rc = flexdyn_subscribe_time(c, 1024)) != FLEXDYN_OK) return fail(c, "subscribe", rc);

    while (done < ticks) {
        rc = flexdyn_wait_tick(c, &t, 300);
        if (rc == FLEXDYN_ENDED) {
            /* The server ended the run and every tick it published was taken. */
            int32_t run_state = 0;
            uint64_t end_tick = 0;
            if (flexdyn_run_ended(c, &run_state, &end_tick) != 1)
                return fail(c, "FLEXDYN_ENDED without an end of run", rc);
            failed = run_state == (int32_t)FD_RUN_STATE_FAILED;
            printf("run ended: %s at tick %llu\n",
                   failed ? "failed"
                          : run_state == (int32_t)FD_RUN_STATE_STOPPED ? "stopped" : "finished",
                   (unsigned long long)end_tick);
            break;
        }
        if (rc == FLEXDYN_ERR_TIMEOUT) {
            /* No tick for 300 ms: only a held server may do that. */
            if (flexdyn_now(c, &now) != FLEXDYN_OK || now.run_state != FD_RUN_STATE_PAUSED)
                return fail(c, "no tick from a running server", rc);
            held_at = now.header.tick;
            ++stalls;
            printf("held at %llu: %s=%llu %s=%llu %s=%llu\n", (unsigned long long)held_at,
                   names[0], (unsigned long long)count[0], names[1],
                   (unsigned long long)count[1], names[2], (unsigned long long)count[2]);
            fflush(stdout);
            if (pause_sent && stalls == 3) {
                rc = flexdyn_send_operator(c, &now.header, FD_OPERATOR_RESUME, 0);
                if (rc != FLEXDYN_OK) return fail(c, "resume", rc);
            }
            continue;
        }
        if (rc != FLEXDYN_OK) return fail(c, "wait_tick", rc);
        if (!started) {
            /* Periods in ticks from the message's frame period; start on a 1 Hz boundary. */
            for (g = 0; g < N_GROUPS; ++g) {
                period[g] = (uint64_t)(1e9 / (rate_hz[g] * (double)t.frame_ns) + 0.5);
                if (period[g] == 0) period[g] = 1;
            }
            if (t.header.tick % period[0] != 0) continue;
            started = 1;
        } else if (t.header.tick != prev + 1) {
            fprintf(stderr, "rate_groups: tick %llu after %llu: a gap\n",
                    (unsigned long long)t.header.tick, (unsigned long long)prev);
            flexdyn_client_free(c);
            return 1;
        }
        prev = t.header.tick;
        /* The rate groups: here each one only counts its runs. */
        for (g = 0; g < N_GROUPS; ++g)
            if (t.header.tick % period[g] == 0) ++count[g];
        ++done;
        if (pause_after != 0 && done == pause_after && !pause_sent) {
            rc = flexdyn_send_operator(c, &t.header, FD_OPERATOR_PAUSE, 0);
            if (rc != FLEXDYN_OK) return fail(c, "pause", rc);
            pause_sent = 1;
        }
    }
    printf("done %s=%llu %s=%llu %s=%llu ticks=%llu stalls=%d held_at=%llu\n", names[0],
           (unsigned long long)count[0], names[1], (unsigned long long)count[1], names[2],
           (unsigned long long)count[2], (unsigned long long)done, stalls,
           (unsigned long long)held_at);
    flexdyn_close(c);
    flexdyn_client_free(c);
    return failed;
}
