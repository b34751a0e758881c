/* t.h - minimal test harness for sw/hsr. */
#ifndef HSR_T_H
#define HSR_T_H
#include <stdio.h>
#include <math.h>
#include "hsr.h"

extern int t_failed_now, t_quick;
extern const char *t_name;
#define CHECK(c) do { if (!(c)) { t_failed_now = 1; \
    fprintf(stderr, "FAIL %s (%s:%d): %s\n", t_name, __FILE__, __LINE__, #c); } } while (0)
#define CHECK_NEAR(a, b, rel) do { double a_ = (a), b_ = (b); \
    if (!(fabs(a_ - b_) <= (rel) * (1 + fabs(a_) + fabs(b_)))) { t_failed_now = 1; \
    fprintf(stderr, "FAIL %s (%s:%d): %s=%.12g vs %s=%.12g\n", t_name, __FILE__, __LINE__, #a, a_, #b, b_); } } while (0)
void t_run(const char *name, void (*fn)(void));
#define RUN(fn) t_run(#fn, fn)

/* helpers (test_main.c) */
hsr_domain *t_poly(const int64_t *xy, int n);          /* one ring */
hsr_domain *t_rect(int64_t l, int64_t b, int64_t r, int64_t t);
double t_bool_area(const hsr_domain *a, const hsr_domain *b, hsr_boolop op);
unsigned t_rand(unsigned long long *s);

void suite_domain(void);
void suite_separate(void);
void suite_grid(void);
void suite_hsr(void);
void suite_props(void);
void suite_io(void);
void suite_obj(void);
void suite_yp(void);
int fuzz_run(int iterations, unsigned long long seed);

/* test_hsr.c helpers */
hsr_ctx *t_ctx(void);
int t_add_rect(hsr_ctx *h, int64_t l, int64_t b, int64_t r, int64_t t, double za, double zc, double op);
double t_visible_area(const hsr_ctx *h, int id);   /* area where id is prefix[0] */
double t_llr_total_area(const hsr_ctx *h);
#endif
