#!/usr/bin/env bash
# The FDIR demo of docs/guides/faults.md ("FDIR demo"): the server runs scenarios/fdir.toml in
# lockstep and flexdyn-acs-demo --fdir flies it; prints the demo's record. Run by
# tests/cli/readme_snippets.rs, which compares the page's lines with what this prints (numbers vary).
set -eu
flexdyn run --config scenarios/fdir.toml --mode lockstep --participants 1 \
    --duration-s 120 --listen tcp/127.0.0.1:17500 >/dev/null 2>&1 &
server=$!
flexdyn-acs-demo --connect tcp/127.0.0.1:17500 --sender-id 1 --fdir \
    --actuator wheels --attitude-source star-tracker --star-tracker st1 \
    --rate-source gyro --imu imu_a --log-every-s 0 --idle-exit-s 5 2>/dev/null
wait "$server"
