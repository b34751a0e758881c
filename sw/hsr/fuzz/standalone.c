/* standalone.c - a libFuzzer-compatible driver for compilers without
 * -fsanitize=fuzzer (gcc): runs every corpus file, then -runs=N mutations
 * of them (byte flips, inserts, deletes, dictionary tokens, splices) from a
 * printed seed.  Not coverage-guided; the real libFuzzer run is `make long`
 * with clang.  A failing input is written to crash-<target>-<seed>-<i> so
 * it can be replayed:  ./fuzz_obj crash-...
 * usage: fuzz_X [-runs=N] [-seed=S] [-max_len=L] FILE_OR_DIR... */
#include <dirent.h>
#include <signal.h>
#include <string.h>
#include <sys/stat.h>
#include "fuzz.h"

typedef struct buf { uint8_t *p; size_t n; } buf;
static buf *corpus; static int ncorpus;
static const char *cur_name = "input";
static uint8_t *cur; static size_t cur_n;

static uint64_t rnd(uint64_t *s) { *s ^= *s << 13; *s ^= *s >> 7; *s ^= *s << 17; return *s; }

static void add_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) { fprintf(stderr, "%s: cannot read\n", path); exit(2); }
    buf b = {malloc(65536), 0};
    b.n = fread(b.p, 1, 65536, f);
    fclose(f);
    corpus = realloc(corpus, sizeof(buf) * (size_t)(ncorpus + 1));
    corpus[ncorpus++] = b;
}

static void add_path(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) { fprintf(stderr, "%s: not found\n", path); exit(2); }
    if (!S_ISDIR(st.st_mode)) { add_file(path); return; }
    DIR *d = opendir(path);
    struct dirent *e;
    while (d && (e = readdir(d))) {
        if (e->d_name[0] == '.') continue;
        char full[4096];
        snprintf(full, sizeof full, "%s/%s", path, e->d_name);
        add_file(full);
    }
    if (d) closedir(d);
}

static void on_abort(int sig)
{
    char name[256];
    snprintf(name, sizeof name, "crash-%s", cur_name);
    FILE *f = fopen(name, "wb");
    if (f) { fwrite(cur, 1, cur_n, f); fclose(f); fprintf(stderr, "input written to %s\n", name); }
    signal(sig, SIG_DFL);
    raise(sig);
}

int main(int argc, char **argv)
{
    long runs = 1000, max_len = 2048;
    uint64_t seed = 1;
    const char *target = strrchr(argv[0], '/') ? strrchr(argv[0], '/') + 1 : argv[0];
    for (int i = 1; i < argc; i++) {
        if (!strncmp(argv[i], "-runs=", 6)) runs = atol(argv[i] + 6);
        else if (!strncmp(argv[i], "-seed=", 6)) seed = strtoull(argv[i] + 6, NULL, 10);
        else if (!strncmp(argv[i], "-max_len=", 9)) max_len = atol(argv[i] + 9);
        else if (argv[i][0] == '-') { fprintf(stderr, "%s: unknown option %s\n", target, argv[i]); return 2; }
        else add_path(argv[i]);
    }
    if (!ncorpus) { fprintf(stderr, "usage: %s [-runs=N] [-seed=S] CORPUS...\n", target); return 2; }
    signal(SIGABRT, on_abort);
    signal(SIGSEGV, on_abort);
    printf("%s: %d corpus inputs, %ld mutations, seed=%llu\n", target, ncorpus, runs, (unsigned long long)seed);
    fflush(stdout);
    static const char *dict[] = {"v ", "f ", "vn ", "usemtl ", "\n", " -", "1e308", "nan", "inf",
                                 "/", "//", "0", "-1", "2147483648", "camera ", "light ", "material ",
                                 "obj ", "screen ", "opacity ", "#", "\xff\x7f", "\x00\x80",
                                 "s ", "s off\n", "mtllib ", "vt ", "1//1 ", "1/1/1 ", "-1//-1 "};
    const size_t ndict = sizeof dict / sizeof dict[0];
    uint8_t *m = malloc((size_t)max_len + 64);
    char name[128];
    for (int i = 0; i < ncorpus; i++) {
        snprintf(name, sizeof name, "%s-corpus-%d", target, i);
        cur_name = name; cur = corpus[i].p; cur_n = corpus[i].n;
        LLVMFuzzerTestOneInput(cur, cur_n);
    }
    uint64_t s = seed * 0x9E3779B97F4A7C15ull + 1;
    for (long r = 0; r < runs; r++) {
        const buf *b = &corpus[rnd(&s) % (uint64_t)ncorpus];
        size_t n = b->n < (size_t)max_len ? b->n : (size_t)max_len;
        memcpy(m, b->p, n);
        int k = 1 + (int)(rnd(&s) % 8);
        for (int j = 0; j < k; j++) {
            size_t at = n ? rnd(&s) % n : 0;
            switch (rnd(&s) % 5) {
            case 0: if (n) m[at] ^= (uint8_t)(1u << (rnd(&s) % 8)); break;
            case 1: if (n) m[at] = (uint8_t)rnd(&s); break;
            case 2: if (n) { memmove(m + at, m + at + 1, n - at - 1); n--; } break;
            case 3: {
                const char *t = dict[rnd(&s) % ndict];
                size_t tl = strlen(t) ? strlen(t) : 1;
                if (n + tl <= (size_t)max_len) { memmove(m + at + tl, m + at, n - at); memcpy(m + at, t, tl); n += tl; }
                break;
            }
            default: {
                const buf *o = &corpus[rnd(&s) % (uint64_t)ncorpus];
                if (o->n && n) { size_t from = rnd(&s) % o->n, l = rnd(&s) % 32;
                    if (from + l > o->n) l = o->n - from;
                    if (at + l > n) l = n - at;
                    memcpy(m + at, o->p + from, l); }
            }
            }
        }
        snprintf(name, sizeof name, "%s-%llu-%ld", target, (unsigned long long)seed, r);
        cur_name = name; cur = m; cur_n = n;
        LLVMFuzzerTestOneInput(m, n);
    }
    printf("%s: %ld runs, no failure\n", target, runs);
    return 0;
}
