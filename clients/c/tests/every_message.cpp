// every_message.cpp - every_message.c compiled as C++17: the same calls, through the same headers,
// from a C++ translation unit (clients/c/tests/c_client.rs, every_message_kind_from_c_and_cpp).
#include "every_message.c"
