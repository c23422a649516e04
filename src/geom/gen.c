/* pdt — deterministic point-set generators.
 *
 * Every family is a pure function of (kind, n, seed): a private splitmix64
 * generator, integer arithmetic only (no libm), so the same call gives the
 * same points on every machine.  The output order is shuffled with the seed
 * (so the sort of the pipeline is exercised), except where noted.
 *
 * Families (coordinates are int32):
 *   uniform       x, y uniform in [0, 2^20).
 *   grid          the first n points of a k x k unit lattice, k = ceil(sqrt n):
 *                 every unit square is cocircular.
 *   circle        EXACT lattice points on circles x^2 + y^2 = r^2 centred at
 *                 the origin.  r is the smallest product of primes = 1 mod 4
 *                 (5, 13, 17, 29, ...) with at least n solutions (their number
 *                 is 4 * prod(2 e_i + 1)), e.g. r = 65 has 36.  The points are
 *                 made from Gaussian-integer factorisations, and a seeded
 *                 subset of n of them is taken.  The richest radius <= 2^30
 *                 (5^2 13 17 29 37 41) has 4860 points; for larger n several
 *                 concentric lattice-rich circles are used (the smallest
 *                 radius that completes n, else the richest unused one).
 *   circle-round  n points spread around a circle of radius 2^20 (seeded
 *                 phase), coordinates rounded to integers: nearly cocircular.
 *   parabola      symmetric: x in [-h, h], y = x^2 (exact, cocircular
 *                 quadruples (+-u, u^2), (+-v, v^2)) while x^2 < 2^31; for
 *                 larger n y = floor(x^2 * 2^30 / X^2) (no longer exact).
 *   clusters      ~sqrt(n)/2 centres uniform in [0, 2^20), points spread
 *                 around them by a sum of four uniforms (bell-shaped).
 *   collinear     half of the points on one line (direction (3, 1)), the
 *                 rest in short collinear runs (3..8 points, small integer
 *                 steps) in random directions.
 *   duplicates    n/2 distinct points in [0, 2^10)^2, the rest copies of
 *                 them (each point appears about twice).
 *   column        half of the points share x = 2^19 (distinct y), the rest
 *                 in eight more columns.
 */
#include "pdt/gen.h"

#include <stdlib.h>
#include <stdio.h>
#include <string.h>

typedef struct rng {
    uint64_t s;
} rng;

static uint64_t rng_next(rng *r)
{
    uint64_t z = (r->s += UINT64_C(0x9e3779b97f4a7c15));
    z = (z ^ (z >> 30)) * UINT64_C(0xbf58476d1ce4e5b9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94d049bb133111eb);
    return z ^ (z >> 31);
}

/* Uniform in [0, m), m > 0 (Lemire's multiply-shift; bias < 2^-32 for our m). */
static uint64_t rng_below(rng *r, uint64_t m)
{
    return (uint64_t)(((unsigned __int128)rng_next(r) * m) >> 64);
}

static void shuffle(pdt_point *p, size_t n, rng *r)
{
    for (size_t i = n; i > 1; i--) {
        size_t j = (size_t)rng_below(r, i);
        pdt_point t = p[i - 1];
        p[i - 1] = p[j];
        p[j] = t;
    }
}

static const char *const kinds[] = {"uniform",  "grid",      "circle",     "circle-round",
                                    "parabola", "clusters",  "collinear",  "duplicates",
                                    "column",   NULL};

const char *const *pdt_gen_kinds(void)
{
    return kinds;
}

#define RANGE20 (UINT64_C(1) << 20)

static void gen_uniform(pdt_point *p, size_t n, rng *r)
{
    for (size_t i = 0; i < n; i++) {
        p[i].x = (int32_t)rng_below(r, RANGE20);
        p[i].y = (int32_t)rng_below(r, RANGE20);
    }
}

static void gen_grid(pdt_point *p, size_t n, rng *r)
{
    size_t k = 1;
    while (k * k < n) k++;
    for (size_t i = 0; i < n; i++) {
        p[i].x = (int32_t)(i % k);
        p[i].y = (int32_t)(i / k);
    }
    shuffle(p, n, r);
}

/* ---- exact lattice circles ---- */

static const struct {
    int64_t p, a, b; /* p = a^2 + b^2, p = 1 mod 4 */
} gprimes[] = {{5, 1, 2},   {13, 2, 3},  {17, 1, 4},  {29, 2, 5},  {37, 1, 6},  {41, 4, 5},
               {53, 2, 7},  {61, 5, 6},  {73, 3, 8},  {89, 5, 8},  {97, 4, 9},  {101, 1, 10},
               {109, 3, 10}, {113, 7, 8}};
#define NGP (sizeof gprimes / sizeof *gprimes)
#define RMAX (INT64_C(1) << 30)

/* Number of lattice points of x^2 + y^2 = r^2 for exponents e. */
static uint64_t lattice_count(const int *e)
{
    uint64_t c = 4;
    for (size_t i = 0; i < NGP; i++) c *= (uint64_t)(2 * e[i] + 1);
    return c;
}

/* A candidate radius: r = prod p_i^e_i <= 2^30. */
typedef struct radius {
    int64_t r;
    uint64_t count;
    uint8_t e[NGP];
    uint8_t used;
} radius;

typedef struct radius_list {
    radius *v;
    size_t n, cap;
    int failed;
} radius_list;

/* Every exponent vector with r <= 2^30 (a few thousand). */
static void radius_enum(radius_list *l, size_t i, int64_t r, int *e)
{
    if (i == NGP) {
        if (l->n == l->cap) {
            size_t cap = l->cap ? 2 * l->cap : 1024;
            radius *t = realloc(l->v, cap * sizeof *t);
            if (!t) {
                l->failed = 1;
                return;
            }
            l->v = t;
            l->cap = cap;
        }
        radius *c = &l->v[l->n++];
        c->r = r;
        c->count = lattice_count(e);
        for (size_t k = 0; k < NGP; k++) c->e[k] = (uint8_t)e[k];
        c->used = 0;
        return;
    }
    int64_t rr = r;
    for (int k = 0;; k++) {
        e[i] = k;
        radius_enum(l, i + 1, rr, e);
        if (rr > RMAX / gprimes[i].p) break;
        rr *= gprimes[i].p;
    }
    e[i] = 0;
}

/* Gaussian integer (x + iy) product. */
static void gmul(int64_t *x, int64_t *y, int64_t a, int64_t b)
{
    int64_t nx = *x * a - *y * b, ny = *x * b + *y * a;
    *x = nx;
    *y = ny;
}

/* Append all lattice points of the circle with exponents e (radius r) to
 * out[*m ...]; out must have room for lattice_count(e) points. */
static void lattice_points(const int *e, pdt_point *out, size_t *m)
{
    /* Enumerate k_i in [0, 2 e_i]: z = prod pi_i^k_i conj(pi_i)^(2 e_i - k_i);
     * then multiply by the four units. */
    int k[NGP];
    memset(k, 0, sizeof k);
    for (;;) {
        int64_t x = 1, y = 0;
        for (size_t i = 0; i < NGP; i++) {
            for (int j = 0; j < k[i]; j++) gmul(&x, &y, gprimes[i].a, gprimes[i].b);
            for (int j = k[i]; j < 2 * e[i]; j++) gmul(&x, &y, gprimes[i].a, -gprimes[i].b);
        }
        /* four rotations by i */
        for (int u = 0; u < 4; u++) {
            out[*m].x = (int32_t)x;
            out[*m].y = (int32_t)y;
            (*m)++;
            int64_t t = x;
            x = -y;
            y = t;
        }
        size_t i = 0;
        while (i < NGP && k[i] == 2 * e[i]) k[i++] = 0;
        if (i == NGP) break;
        k[i]++;
    }
}

static pdt_status gen_circle(pdt_point **pp, size_t n, rng *r, pdt_err *err)
{
    /* Collect circles until they hold >= n points: the smallest radius with
     * enough lattice points for the rest, or else the richest unused radius,
     * and repeat. */
    radius_list l = {NULL, 0, 0, 0};
    int e[NGP];
    memset(e, 0, sizeof e);
    radius_enum(&l, 0, 1, e);
    pdt_point *all = malloc(sizeof *all);
    size_t m = 0, cap = 1;
    pdt_status st = PDT_OK;
    if (!all || l.failed) st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    while (st == PDT_OK && m < n) {
        radius *best = NULL, *rich = NULL;
        for (size_t k = 0; k < l.n; k++) {
            radius *c = &l.v[k];
            if (c->used) continue;
            if (c->count >= n - m && (!best || c->r < best->r)) best = c;
            if (!rich || c->count > rich->count || (c->count == rich->count && c->r < rich->r))
                rich = c;
        }
        radius *use = best ? best : rich;
        if (!use) {
            st = pdt_err_set(err, PDT_ERR_ARG, "circle: %zu points do not fit on "
                             "lattice circles of radius <= 2^30", n);
            break;
        }
        use->used = 1;
        if (m + use->count > cap) {
            cap = m + use->count;
            pdt_point *t = realloc(all, cap * sizeof *t);
            if (!t) {
                st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
                break;
            }
            all = t;
        }
        for (size_t k = 0; k < NGP; k++) e[k] = use->e[k];
        lattice_points(e, all, &m);
    }
    free(l.v);
    if (st != PDT_OK) {
        free(all);
        return st;
    }
    /* Seeded subset of n: shuffle, keep the first n. */
    shuffle(all, m, r);
    if (n) {
        pdt_point *t = realloc(all, n * sizeof *t);
        if (t) all = t;
    }
    *pp = all;
    return PDT_OK;
}

/* Integer square root, floor. */
static uint64_t isqrt(uint64_t v)
{
    uint64_t x = 0, b = UINT64_C(1) << 62;
    while (b > v) b >>= 2;
    while (b) {
        if (v >= x + b) {
            v -= x + b;
            x = (x >> 1) + b;
        } else {
            x >>= 1;
        }
        b >>= 2;
    }
    return x;
}

/* sqrt(v) rounded to the nearest integer. */
static int64_t rsqrt(uint64_t v)
{
    uint64_t s = isqrt(v);
    /* (s + 1/2)^2 = s^2 + s + 1/4 < v  <=>  s^2 + s < v (integers) */
    if (s * s + s < v) s++;
    return (int64_t)s;
}

static void gen_circle_round(pdt_point *p, size_t n, rng *r)
{
    /* No libm: the circle of radius R = 2^20 is split into 8 octants; within
     * an octant the coordinate that changes slowly goes in equal steps and the
     * other is sqrt(R^2 - t^2) rounded to the nearest integer.  A seeded phase
     * shifts the start. */
    const int64_t R = INT64_C(1) << 20;
    const int64_t H = 741455; /* floor(R / sqrt 2) */
    uint64_t phase = rng_below(r, 1u << 16);
    for (size_t i = 0; i < n; i++) {
        uint64_t pos = ((uint64_t)i * 8 * (uint64_t)H) / n + phase;
        pos %= 8 * (uint64_t)H;
        int oct = (int)(pos / (uint64_t)H);
        int64_t t = (int64_t)(pos % (uint64_t)H);
        int64_t s = rsqrt((uint64_t)(R * R - t * t));
        int64_t u = H - t, su = rsqrt((uint64_t)(R * R - u * u));
        int64_t x, y;
        switch (oct) { /* counter-clockwise through the octants */
        case 0: x = s; y = t; break;
        case 1: x = u; y = su; break;
        case 2: x = -t; y = s; break;
        case 3: x = -su; y = u; break;
        case 4: x = -s; y = -t; break;
        case 5: x = -u; y = -su; break;
        case 6: x = t; y = -s; break;
        default: x = su; y = -u; break;
        }
        p[i].x = (int32_t)x;
        p[i].y = (int32_t)y;
    }
    shuffle(p, n, r);
}

static void gen_parabola(pdt_point *p, size_t n, rng *r)
{
    int64_t h = (int64_t)(n / 2);
    for (size_t i = 0; i < n; i++) {
        int64_t x = (int64_t)i - h;
        p[i].x = (int32_t)x;
        if (h <= 46340)
            p[i].y = (int32_t)(x * x);
        else
            p[i].y = (int32_t)(((unsigned __int128)(x * x) << 30) / (uint64_t)(h * h));
    }
    shuffle(p, n, r);
}

/* Bell-shaped offset in (-2w, 2w): sum of four uniforms. */
static int64_t bell(rng *r, uint64_t w)
{
    int64_t s = 0;
    for (int k = 0; k < 4; k++) s += (int64_t)rng_below(r, w + 1);
    return s - 2 * (int64_t)w;
}

static void gen_clusters(pdt_point *p, size_t n, rng *r)
{
    size_t k = (size_t)isqrt(n) / 2;
    if (k < 1) k = 1;
    uint64_t base = rng_next(r);
    for (size_t i = 0; i < n; i++) {
        size_t j = (size_t)rng_below(r, k);
        rng cj = {base + (uint64_t)j * UINT64_C(0x9e3779b97f4a7c15)}; /* centre j */
        int64_t cx = (int64_t)rng_below(&cj, RANGE20), cy = (int64_t)rng_below(&cj, RANGE20);
        p[i].x = (int32_t)(cx + bell(r, 1u << 12));
        p[i].y = (int32_t)(cy + bell(r, 1u << 12));
    }
}

static void gen_collinear(pdt_point *p, size_t n, rng *r)
{
    size_t half = n < 6 ? n : n / 2;
    int64_t x0 = (int64_t)rng_below(r, 1000), y0 = (int64_t)rng_below(r, 1000);
    for (size_t i = 0; i < half; i++) {
        int64_t t = (int64_t)rng_below(r, RANGE20 / 3);
        p[i].x = (int32_t)(x0 + 3 * t);
        p[i].y = (int32_t)(y0 + t);
    }
    size_t i = half;
    while (i < n) {
        size_t len = 3 + (size_t)rng_below(r, 6);
        int64_t sx = (int64_t)rng_below(r, RANGE20), sy = (int64_t)rng_below(r, RANGE20);
        int64_t dx = (int64_t)rng_below(r, 9) - 4, dy = (int64_t)rng_below(r, 9) - 4;
        if (dx == 0 && dy == 0) dx = 1;
        int64_t step = 1 + (int64_t)rng_below(r, 64);
        for (size_t k = 0; k < len && i < n; k++, i++) {
            p[i].x = (int32_t)(sx + (int64_t)k * dx * step);
            p[i].y = (int32_t)(sy + (int64_t)k * dy * step);
        }
    }
    shuffle(p, n, r);
}

static void gen_duplicates(pdt_point *p, size_t n, rng *r)
{
    size_t base = (n + 1) / 2;
    for (size_t i = 0; i < base; i++) {
        p[i].x = (int32_t)rng_below(r, 1024);
        p[i].y = (int32_t)rng_below(r, 1024);
    }
    for (size_t i = base; i < n; i++) p[i] = p[rng_below(r, base)];
    shuffle(p, n, r);
}

static void gen_column(pdt_point *p, size_t n, rng *r)
{
    size_t half = (n + 1) / 2;
    for (size_t i = 0; i < n; i++) {
        int64_t x = (int64_t)(RANGE20 / 2);
        if (i >= half) x = (int64_t)(rng_below(r, 9) * (RANGE20 / 8));
        p[i].x = (int32_t)x;
        p[i].y = (int32_t)rng_below(r, RANGE20);
    }
    shuffle(p, n, r);
}

pdt_status pdt_gen(const char *kind, size_t n, uint64_t seed, pdt_point **pts, pdt_err *err)
{
    *pts = NULL;
    if (!kind) kind = "";
    size_t k = 0;
    while (kinds[k] && strcmp(kinds[k], kind) != 0) k++;
    if (!kinds[k]) {
        char list[512];
        size_t len = 0;
        list[0] = '\0';
        for (size_t i = 0; kinds[i]; i++) {
            int w = snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "", kinds[i]);
            if (w > 0) len += (size_t)w;
        }
        return pdt_err_set(err, PDT_ERR_ARG, "unknown kind '%s' (kinds: %s)", kind, list);
    }
    if (n > UINT32_MAX)
        return pdt_err_set(err, PDT_ERR_ARG, "n = %zu is too large", n);
    rng r = {seed ^ UINT64_C(0x6a09e667f3bcc909)};
    if (strcmp(kind, "circle") == 0) return gen_circle(pts, n, &r, err);
    pdt_point *p = malloc((n ? n : 1) * sizeof *p);
    if (!p) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    switch (k) {
    case 0: gen_uniform(p, n, &r); break;
    case 1: gen_grid(p, n, &r); break;
    case 3: gen_circle_round(p, n, &r); break;
    case 4: gen_parabola(p, n, &r); break;
    case 5: gen_clusters(p, n, &r); break;
    case 6: gen_collinear(p, n, &r); break;
    case 7: gen_duplicates(p, n, &r); break;
    default: gen_column(p, n, &r); break;
    }
    *pts = p;
    return PDT_OK;
}
