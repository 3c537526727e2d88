// fsw.cpp - fsw.c compiled as C++17: the flight-code telemetry calls through the same headers,
// from a C++ translation unit (clients/c/tests/c_client.rs, fsw_telemetry_from_c_is_recorded_bit_for_bit).
#include "fsw.c"
