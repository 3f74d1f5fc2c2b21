/* Overlapping Allan variance sums at octave averaging factors (m = 1, 2, 4, ...).
 *
 * Private to hrgtc.evaluation (_allan_sums.py calls it); built by `pip install -e .`
 * (setup.py). Why C and not numba: a whole command that computes an octave Allan
 * deviation spends ~0.7 s in numba's import and kernel loading alone, more than the
 * arithmetic (docs/architecture.md, "The native Allan module").
 *
 * Method (pairwise doubling, no phase array). With y'[k] = y[k] - mu and the phase
 * X[k] = sum_{l<k} y'[l], the block sums S_m[i] = X[i+m] - X[i] (i = 0..N-m) give the
 * second difference of SP 1065 Eq. (11) as d_i = X[i+2m] - 2X[i+m] + X[i] =
 * S_m[i+m] - S_m[i], and the next octave as S_2m[i] = S_m[i] + S_m[i+m]. S_1 = y', so
 * every level is one subtraction and one addition of two stored numbers: S_m is a
 * balanced pairwise sum of m values of y' (rounding error ~ sqrt(log2 m) eps in the
 * relative sense), never a difference of two large phase values, so no digits are lost
 * where a float64 phase loses them (a large offset or drift). GROUP levels are fused into
 * one pass over the work array (S_m, S_2m, S_4m at i from S_m at i, i+m, i+2m, i+3m);
 * S is overwritten in place (ascending i reads each value before it is replaced).
 *
 * The squares d_i^2 are summed in float64 in 2 x 4 lanes over fixed chunks of CHUNK
 * terms; the chunk sums are added in index order with Neumaier's compensated sum [2].
 * One thread: two (each taking half of the chunks of the passes after the sweep) were
 * slower at 10^7 samples on a shared two-core machine and no faster at 10^8.
 *
 * [1] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065, 2008.
 * [2] A. Neumaier, "Rundungsfehleranalyse einiger Verfahren zur Summation endlicher
 *     Summen", ZAMM 54, 39-51, 1974.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef __linux__
#include <sys/mman.h>
#endif

#define GROUP 2          /* octave levels fused into one pass over the work array (1 or 2;
                            2 was faster than 1 and 3 at 10^7 samples, docs/benchmarks.md) */
#define CHUNK 32768L     /* terms per partial sum (float64), the partial sums compensated */
#define SWEEP_M 65536L   /* groups from factors up to this one are swept together */
#define MAX_LEVELS 62

/* The AVX2 clone where the CPU has it (picked at load time), SSE2 otherwise; no FMA is
 * enabled in either, and setup.py passes -ffp-contract=off: the rounding is as written. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__linux__)
#define CLONES __attribute__((target_clones("avx2", "default")))
#else
#define CLONES
#endif

typedef double v4 __attribute__((vector_size(32), aligned(8), may_alias));

/* One chunk of `count` terms with L fused levels: d of level l at i is
 * S[i + 2^l m] - S[i] of that level's S; out[l] += the chunk's sum of d^2. `src` and
 * `dst` point at the chunk's first term; dst (if not NULL) receives S_{2^L m}. */
#define SPAN(L)                                                                         \
    static inline __attribute__((always_inline)) void span##L(                          \
        const double *src, double *dst, double mu, long m, long count, double *out,     \
        const int shift)                                                                \
    {                                                                                   \
        v4 acc[L][2];                                                                   \
        double rest[L];                                                                 \
        const v4 vmu = {mu, mu, mu, mu};                                                \
        long i = 0;                                                                     \
        for (int l = 0; l < L; l++) {                                                   \
            acc[l][0] = acc[l][1] = (v4){0.0, 0.0, 0.0, 0.0};                           \
            rest[l] = 0.0;                                                              \
        }                                                                               \
        for (; i + 8 <= count; i += 8) {                                                \
            for (int a = 0; a < 2; a++) {                                               \
                v4 v[1 << L];                                                           \
                for (int j = 0; j < (1 << L); j++)                                      \
                    v[j] = *(const v4 *)(src + i + 4 * a + j * m);                      \
                for (int j = 0; j < (1 << L) && shift; j++) v[j] -= vmu;                \
                for (int l = 0, n = 1 << L; l < L; l++) {                               \
                    v4 d = v[1] - v[0];                                                 \
                    acc[l][a] += d * d;                                                 \
                    n >>= 1;                                                            \
                    for (int j = 0; j < n; j++) v[j] = v[2 * j] + v[2 * j + 1];         \
                }                                                                       \
                if (dst) *(v4 *)(dst + i + 4 * a) = v[0];                               \
            }                                                                           \
        }                                                                               \
        for (; i < count; i++) {                                                        \
            double v[1 << L];                                                           \
            for (int j = 0; j < (1 << L); j++) v[j] = shift ? src[i + j * m] - mu       \
                                                            : src[i + j * m];           \
            for (int l = 0, n = 1 << L; l < L; l++) {                                   \
                double d = v[1] - v[0];                                                 \
                rest[l] += d * d;                                                       \
                n >>= 1;                                                                \
                for (int j = 0; j < n; j++) v[j] = v[2 * j] + v[2 * j + 1];             \
            }                                                                           \
            if (dst) dst[i] = v[0];                                                     \
        }                                                                               \
        for (int l = 0; l < L; l++) {                                                   \
            v4 s = acc[l][0] + acc[l][1];                                               \
            out[l] = ((s[0] + s[1]) + (s[2] + s[3])) + rest[l];                         \
        }                                                                               \
    }

SPAN(1)
SPAN(2)

CLONES static void chunk(const double *src, double *dst, double mu, long m, long count,
                         int levels, double *out)
{
    /* mu = 0 (the groups after the first): no subtraction at all, 4 vector ops fewer */
    if (levels == 2 && mu != 0.0)
        span2(src, dst, mu, m, count, out, 1);
    else if (levels == 2)
        span2(src, dst, mu, m, count, out, 0);
    else if (mu != 0.0)
        span1(src, dst, mu, m, count, out, 1);
    else
        span1(src, dst, mu, m, count, out, 0);
}

typedef struct {
    double sum, compensation;
} Compensated;

static void neumaier_add(Compensated *acc, double value)
{
    double t = acc->sum + value;
    if (fabs(acc->sum) >= fabs(value))
        acc->compensation += (acc->sum - t) + value;
    else
        acc->compensation += (value - t) + acc->sum;
    acc->sum = t;
}

/* A span of one group: the terms [i0, i1) of `levels` levels from factor m, cut into
 * chunks; part[l * nchunks + c] holds chunk c's sum of level l. */
typedef struct {
    const double *src;
    double *dst;          /* the group's S_{2^levels m} (the next group's input), or NULL */
    double mu;
    long m, i0, i1, nchunks;
    int levels, group, first;  /* first: the index of the span's level 0 among all levels */
    double *part;
} Span;

/* The chunks [c0, c1) of a span (dst == src: in place, ascending). */
static void run_chunks(const Span *p, long c0, long c1)
{
    double out[GROUP];
    for (long c = c0; c < c1; c++) {
        long a = p->i0 + c * CHUNK;
        long b = a + CHUNK < p->i1 ? a + CHUNK : p->i1;
        chunk(p->src + a, p->dst ? p->dst + a : NULL, p->mu, p->m, b - a, p->levels, out);
        for (int l = 0; l < p->levels; l++) p->part[l * p->nchunks + c] = out[l];
    }
}

/* The spans of the groups [0, groups) in one sweep, one chunk of group 0 at a time, each
 * later group as far as its input (the group before's output) is written: the work array
 * is read and written once for all of them while its values are in the cache (the
 * groups' look-ahead, 3 m each, ~2 MB up to SWEEP_M, stays in L2 and L3; SWEEP_M 4096
 * took 18% longer at 10^7 samples, 2^18 and 2^20 no less). One thread. */
static void sweep(const Span *spans, int count, int groups)
{
    long frontier[MAX_LEVELS];  /* the group's S is written below this index */
    int next[MAX_LEVELS];       /* the group's next span (spans are in group order) */
    long chunk[MAX_LEVELS];     /* and its next chunk there */
    int left = 0;
    for (int g = 0; g < groups; g++) {
        frontier[g] = 0;
        next[g] = count;
        chunk[g] = 0;
    }
    for (int s = count - 1; s >= 0; s--)
        if (spans[s].group < groups) {
            next[spans[s].group] = s;
            left++;
        }
    while (left > 0) {
        for (int g = 0; g < groups; g++) {
            for (int budget = g == 0 ? 1 : 1 << 30; budget > 0 && next[g] < count &&
                                                    spans[next[g]].group == g; budget--) {
                const Span *p = &spans[next[g]];
                long a = p->i0 + chunk[g] * CHUNK;
                long b = a + CHUNK < p->i1 ? a + CHUNK : p->i1;
                if (g > 0 && b - 1 + ((1L << p->levels) - 1) * p->m >= frontier[g - 1]) break;
                run_chunks(p, chunk[g], chunk[g] + 1);
                if (p->dst) frontier[g] = b;
                if (++chunk[g] == p->nchunks) {
                    if (p->dst) frontier[g] = LONG_MAX;  /* all of the group's S written */
                    next[g]++;
                    chunk[g] = 0;
                    left--;
                }
            }
        }
    }
}

/* The work array: 2 MiB-aligned and backed by huge pages where Linux offers them (one
 * page fault per 2 MiB instead of per 4 KiB: ~15 instead of ~70 ms for 10^7 values). */
static double *work_array(long n)
{
    size_t bytes = sizeof(double) * (size_t)(n > 0 ? n : 1);
    void *p = NULL;
    if (posix_memalign(&p, 1 << 21, bytes) != 0) return NULL;
#ifdef MADV_HUGEPAGE
    madvise(p, bytes, MADV_HUGEPAGE);
#endif
    return p;
}

/* Sums of d^2 at m = 1, 2, ..., 2^(levels-1) of the n values y (y' = y - mu). */
static int octave(const double *y, long n, double mu, int levels, double *sums)
{
    Span spans[MAX_LEVELS];
    Compensated acc[MAX_LEVELS] = {{0.0, 0.0}};
    int count = 0, swept = 0, status = -1;
    double *work = levels > GROUP ? work_array(n) : NULL;
    if (levels > GROUP && !work) return -1;
    long m = 1;
    for (int first = 0, g = 0; first < levels; first += GROUP, g++, m <<= GROUP) {
        int group = levels - first < GROUP ? levels - first : GROUP;
        int last = first + group == levels;
        if (m <= SWEEP_M) swept = g + 1;
        /* level l of the group has terms i <= n - 2^(l+1) m; the group's S_{2^group m}
         * (the next group's input) is needed for i <= n - 2^group m: the full-group span */
        long done = 0;
        for (int l = group; l >= 1; l--) {
            long end = n - (1L << l) * m + 1;
            if (end > done) {
                spans[count++] = (Span){first ? work : y, l == group && !last ? work : NULL,
                                        first ? 0.0 : mu, m, done, end,
                                        (end - done + CHUNK - 1) / CHUNK, l, g, first, NULL};
                done = end;
            }
        }
    }
    for (int s = 0; s < count; s++)
        if (!(spans[s].part = malloc(sizeof(double) * (size_t)(spans[s].levels *
                                                                spans[s].nchunks))))
            goto out;
    sweep(spans, count, swept);
    for (int s = 0; s < count; s++)  /* the larger factors: one pass over the array each */
        if (spans[s].group >= swept) run_chunks(&spans[s], 0, spans[s].nchunks);
    for (int s = 0; s < count; s++)  /* in span order: each level's chunks in index order */
        for (int l = 0; l < spans[s].levels; l++)
            for (long c = 0; c < spans[s].nchunks; c++)
                neumaier_add(&acc[spans[s].first + l], spans[s].part[l * spans[s].nchunks + c]);
    for (int l = 0; l < levels; l++) sums[l] = acc[l].sum + acc[l].compensation;
    status = 0;
out:
    for (int s = 0; s < count; s++) free(spans[s].part);
    free(work);
    return status;
}

static PyObject *octave_sums(PyObject *self, PyObject *args)
{
    PyObject *data;
    double mu;
    int levels;
    (void)self;
    if (!PyArg_ParseTuple(args, "Odi", &data, &mu, &levels)) return NULL;
    Py_buffer view;
    if (PyObject_GetBuffer(data, &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) != 0) return NULL;
    PyObject *result = NULL;
    long n = (long)(view.len / (Py_ssize_t)sizeof(double));
    if (view.ndim != 1 || view.itemsize != sizeof(double) || !view.format ||
        strcmp(view.format, "d") != 0) {
        PyErr_SetString(PyExc_TypeError, "octave_sums needs a contiguous 1-D float64 array");
    } else if (levels < 1 || levels > MAX_LEVELS || n + 1 - 2 * (1L << (levels - 1)) < 1) {
        PyErr_Format(PyExc_ValueError,
                     "%d octave levels leave no term in %ld samples", levels, n);
    } else {
        double sums[MAX_LEVELS];
        int status;
        Py_BEGIN_ALLOW_THREADS
        status = octave((const double *)view.buf, n, mu, levels, sums);
        Py_END_ALLOW_THREADS
        if (status != 0) {
            PyErr_NoMemory();
        } else if ((result = PyList_New(levels)) != NULL) {
            for (int l = 0; l < levels; l++) PyList_SET_ITEM(result, l, PyFloat_FromDouble(sums[l]));
        }
    }
    PyBuffer_Release(&view);
    return result;
}

static PyMethodDef methods[] = {
    {"octave_sums", octave_sums, METH_VARARGS,
     "octave_sums(y, mean, levels) -> list of float\n\n"
     "Sum over i of (X[i+2m] - 2X[i+m] + X[i])^2 for m = 1, 2, ..., 2**(levels-1), X the\n"
     "phase of y - mean (SP 1065 Eq. 11); y a contiguous 1-D float64 buffer."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_allan_octave",
    "Overlapping Allan variance sums at octave factors (see _allan_octave.c).", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__allan_octave(void) { return PyModule_Create(&module); }
