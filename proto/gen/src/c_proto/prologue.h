/*
 * flexdyn_proto.h - the flexdyn wire protocol (version {VERSION}) for C99 and C++ flight code.
 *
 * {GENERATED}: the constants, structs, decoders, encoders, validators and keys come from the
 * table; the prose, the byte helpers and the error type from the .h files of
 * proto/gen/src/c_proto/.
 *
 * Header-only: include it and call fd_decode_* / fd_encode_*. No allocation, no I/O, no
 * global state. Bytes are assembled one by one (little-endian on the wire), never cast to a
 * struct, so it is correct on big-endian hosts too. The byte tables are in proto/README.md;
 * this file follows them and the decoder rules there in the same order, with the same error
 * reasons as the Rust crate's DecodeError:
 *
 *   1. more than FD_MAX_MESSAGE_BYTES                      -> FD_ERR_TOO_LARGE
 *   2. fewer than 2 bytes                                   -> FD_ERR_LENGTH
 *      first two bytes (u16 LE) != FD_PROTOCOL_VERSION      -> FD_ERR_UNKNOWN_VERSION
 *   3. total length from the layout (fixed, tag, walked counts; every count bounded first)
 *      buffer shorter                                       -> FD_ERR_LENGTH (needed = length
 *                                                              implied by the counts read)
 *      unknown command tag, count above its maximum         -> FD_ERR_MALFORMED
 *      buffer longer                                        -> FD_ERR_TRAILING_BYTES
 *   4. fields in wire order: an enum tag out of range or a bool byte other than 0/1
 *                                                           -> FD_ERR_MALFORMED
 *   5. CommandMsg: a non-finite torque, force or input value (in that order)
 *      FaultCommandMsg: a non-finite params value (since protocol 8)
 *                                                           -> FD_ERR_NON_FINITE (field named)
 *
 * Decoders write into caller storage; a StateMsg's effectors and an Actuators command's inputs
 * go into arrays the caller provides (capacity given), FD_ERR_CAPACITY if they do not fit (a C-only
 * reason, checked after the wire rules). Compile with -std=c99 -Wall -Wextra -pedantic.
 *
 * C++: the same file compiles as C++ (C++98 on; nullptr from C++11) without a warning under the
 * stricter lints C++ teams use: -Wold-style-cast, -Wzero-as-null-pointer-constant (clang, and
 * compilers whose NULL is a plain 0), -Wuseless-cast (g++), -Wconversion, -Wsign-conversion.
 * Casts are written FD_CAST(type, value), which is static_cast in C++; null pointers FD_NULL,
 * which is nullptr from C++11 on. Every function is static inline (internal linkage, nothing to
 * link), so there is no extern "C" block: it would add nothing, and g++ does not apply
 * -Wold-style-cast inside one, which would hide regressions from the C++ check.
 *
 * Lockstep flight code: compute the answer to tick k from the StateMsg of tick k together with
 * every sensor sample due at tick k. proto/README.md, "Lockstep protocol", says how: one
 * subscriber on all of flexdyn/<sc>/tlm (the key expression ending in a double star), and the
 * sensors and their rates from the flexdyn/<sc>/config queryable.
 */
#ifndef FLEXDYN_PROTO_H
#define FLEXDYN_PROTO_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* Casts and null pointers that suit both languages (see the C++ note above). */
#ifdef __cplusplus
#define FD_CAST(type, value) (static_cast<type>(value))
#if __cplusplus >= 201103L || (defined(_MSVC_LANG) && _MSVC_LANG >= 201103L)
#define FD_NULL nullptr
#else
#define FD_NULL NULL
#endif
#else
#define FD_CAST(type, value) ((type)(value))
#define FD_NULL NULL
#endif

