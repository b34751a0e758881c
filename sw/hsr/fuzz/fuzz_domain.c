/* fuzz_domain.c - domain construction and the boolean operations on
 * arbitrary (degenerate, self-intersecting, repeated-point) rings.
 * Input: byte 0 = number of rings of A (1..3, the rest go to B), then
 * little-endian int16 pairs scaled by a factor from byte 1, ring lengths
 * from the following bytes.  Invariants: the area identities
 * |A u B| + |A n B| = |A| + |B|, A xor A = empty, |A - B| = |A| - |A n B|,
 * and point containment is consistent with the intersection. */
#include <math.h>
#include <string.h>
#include "hsr.h"
#include "fuzz.h"

#define MAXP 64

static hsr_domain *take(const uint8_t **p, const uint8_t *end, int64_t scale)
{
    int64_t xy[2 * MAXP];
    int len[3], nr = 0, np = 0;
    while (nr < 3 && *p < end) {
        int n = **p % 12, got = 0;
        (*p)++;
        for (; got < n && np < MAXP && *p + 4 <= end; got++, np++) {
            int16_t x = (int16_t)((*p)[0] | (*p)[1] << 8), y = (int16_t)((*p)[2] | (*p)[3] << 8);
            xy[2 * np] = x * scale; xy[2 * np + 1] = y * scale;
            *p += 4;
        }
        len[nr++] = got;
        if (*p < end && (**p & 0x80)) { (*p)++; break; }
    }
    hsr_domain *d = NULL;
    hsr_status st = hsr_domain_from_rings(xy, len, nr, &d);
    FUZZ_ASSERT(st == HSR_OK || st == HSR_ERANGE || st == HSR_ENOMEM || (st == HSR_EINVAL && nr == 0));
    return st == HSR_OK ? d : NULL;
}

static double area_of(const hsr_domain *a, const hsr_domain *b, hsr_boolop op)
{
    hsr_domain *r = NULL;
    FUZZ_ASSERT(hsr_domain_boolean(a, b, op, &r) == HSR_OK);
    double v = hsr_domain_area(r);
    hsr_domain_free(r);
    return v;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 2 || size > 2048) return 0;
    const int64_t scales[4] = {1, 16, 4096, 256};
    int64_t scale = scales[data[1] % 4];
    const uint8_t *p = data + 2, *end = data + size;
    hsr_domain *a = take(&p, end, scale), *b = take(&p, end, scale);
    if (a && b) {
        double A = hsr_domain_area(a), B = hsr_domain_area(b);
        double U = area_of(a, b, HSR_UNION), I = area_of(a, b, HSR_INTERSECT);
        double D = area_of(a, b, HSR_SUBTRACT), X = area_of(a, a, HSR_XOR);
        double tol = 1e-9 * (1 + A + B);
        FUZZ_ASSERT(A >= 0 && B >= 0 && I <= fmin(A, B) + tol && U + tol >= fmax(A, B));
        FUZZ_ASSERT(fabs(U + I - A - B) <= tol);
        FUZZ_ASSERT(fabs(D - (A - I)) <= tol);
        FUZZ_ASSERT(X == 0);
        hsr_extent e = hsr_domain_extent(a);
        int64_t px = (e.left + e.right) / 2, py = (e.bot + e.top) / 2;
        if (hsr_domain_contains(a, px, py) && hsr_domain_contains(b, px, py)) FUZZ_ASSERT(I > 0);
    }
    hsr_domain_free(a);
    hsr_domain_free(b);
    return 0;
}
