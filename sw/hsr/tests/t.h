/* t.h - minimal test harness of the C libraries (sw/hsr, sw/yproc; t.c). */
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
int t_report(void);                 /* prints "N passed, M failed"; 1 if any failed */
#define RUN(fn) t_run(#fn, fn)

/* helpers (test_main.c) */
hsr_domain *t_poly(const int64_t *xy, int n);          /* one ring */
hsr_domain *t_rect(int64_t l, int64_t b, int64_t r, int64_t t);
double t_bool_area(const hsr_domain *a, const hsr_domain *b, hsr_boolop op);
unsigned t_rand(unsigned long long *s);
/* the OBJ test meshes (dir: sw/hsr/tests/obj, as the caller sees it) in a 32x16 scene */
#define T_OBJ_SCENE_HEAD "screen 32 16\ncamera eye 1.5 1.2 6 at 0 0 0 up 0 1 0 fov 42\nlight 0.3 0.5 0.8 0.7\n" \
                         "ambient 0.2\nmaterial green 0.1 0.7 0.2\nmaterial grey 0.75 0.75 0.75\n"
hsr_scene *t_load_obj(const char *dir, const char *obj, char *err, size_t n);

void suite_domain(void);
void suite_separate(void);
void suite_grid(void);
void suite_hsr(void);
void suite_props(void);
void suite_io(void);
void suite_obj(void);
void suite_yp(void);            /* sw/yproc/tests */
void suite_obj_shading(void);
int fuzz_run(int iterations, unsigned long long seed);

/* test_hsr.c helpers */
hsr_ctx *t_ctx(void);
int t_add_rect(hsr_ctx *h, int64_t l, int64_t b, int64_t r, int64_t t, double za, double zc, double op);
double t_visible_area(const hsr_ctx *h, int id);   /* area where id is prefix[0] */
double t_llr_total_area(const hsr_ctx *h);
#endif
