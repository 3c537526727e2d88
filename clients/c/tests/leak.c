/*
 * leak.c - a handle that is never freed. The leak test links it with the same sanitizer as the
 * 10,000-tick run and expects the leak to be reported, so a silent leak checker (one that does
 * not see the library's allocations) fails the test instead of passing it.
 */
#include "flexdyn_client.h"

int main(void) {
    flexdyn_client *c = flexdyn_client_new();
    c = 0; /* the only pointer to it is gone */
    return c == 0 ? 0 : 1;
}
