/* fuzz.h - libFuzzer-style targets of sw/hsr.  Each target file defines
 * LLVMFuzzerTestOneInput(); it returns 0 and abort()s (via FUZZ_ASSERT) when an
 * invariant breaks, so libFuzzer (clang -fsanitize=fuzzer) and the gcc
 * stand-alone driver (standalone.c) both report it as a crash. */
#ifndef HSR_FUZZ_H
#define HSR_FUZZ_H
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define FUZZ_ASSERT(c) do { if (!(c)) { \
    fprintf(stderr, "fuzz invariant failed (%s:%d): %s\n", __FILE__, __LINE__, #c); \
    abort(); } } while (0)

/* NUL-terminated heap copy of the input (the parsers take C strings). */
static inline char *fuzz_cstr(const uint8_t *data, size_t size)
{
    char *s = malloc(size + 1);
    if (!s) return NULL;
    for (size_t i = 0; i < size; i++) s[i] = (char)data[i];
    s[size] = 0;
    return s;
}
#endif
