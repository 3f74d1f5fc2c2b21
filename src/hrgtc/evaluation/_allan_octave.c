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
 * terms; the chunk sums are added in index order with Neumaier's compensated sum. The
 * chunks do not depend on the number of threads, so neither do the sums (bit for bit).
 * Two threads share the chunks of each pass; the second writes the values the first
 * still reads into a side buffer, copied in place after both are done.
 *
 * [1] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065, 2008.
 * [2] A. Neumaier, "Rundungsfehleranalyse einiger Verfahren zur Summation endlicher
 *     Summen", ZAMM 54, 39-51, 1974.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#ifdef __linux__
#include <sys/mman.h>
#endif

#ifndef GROUP           /* octave levels fused into one pass over the work array (1-3) */
#define GROUP 2
#endif
#define CHUNK 32768L     /* terms per partial sum: fixed, so the sums ignore the threads */
#define MAX_THREADS 2
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
        const double *src, double *dst, double mu, long m, long count, double *out)     \
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
                    v[j] = *(const v4 *)(src + i + 4 * a + j * m) - vmu;                \
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
            for (int j = 0; j < (1 << L); j++) v[j] = src[i + j * m] - mu;              \
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
SPAN(3)

CLONES static void chunk(const double *src, double *dst, double mu, long m, long count,
                         int levels, double *out)
{
    if (levels == 3)
        span3(src, dst, mu, m, count, out);
    else if (levels == 2)
        span2(src, dst, mu, m, count, out);
    else
        span1(src, dst, mu, m, count, out);
}

/* One worker's share of a pass: chunks [c0, c1) of the terms [i0, i1). */
typedef struct {
    const double *src;
    double *dst;          /* NULL: nothing stored */
    double *side;         /* stores of chunks [c_side, c_side_end) go to the side buffer */
    double mu;
    long m, i0, i1, c0, c1, c_side, c_side_end, nchunks;
    int levels;
    double *part;         /* part[l * nchunks + c]: chunk c's sum of level l */
} Share;

static void *run_share(void *arg)
{
    Share *s = arg;
    double out[GROUP];
    long side_start = s->i0 + s->c_side * CHUNK;
    for (long c = s->c0; c < s->c1; c++) {
        long a = s->i0 + c * CHUNK;
        long b = a + CHUNK < s->i1 ? a + CHUNK : s->i1;
        double *dst = NULL;
        if (s->dst)
            dst = s->side && c >= s->c_side && c < s->c_side_end ? s->side + (a - side_start) : s->dst + a;
        chunk(s->src + a, dst, s->mu, s->m, b - a, s->levels, out);
        for (int l = 0; l < s->levels; l++) s->part[l * s->nchunks + c] = out[l];
    }
    return NULL;
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

/* The terms [i0, i1) of `levels` levels (from factor m) in one pass; their chunk sums
 * added to acc[0..levels). dst == src: in place. Returns 0, or -1 if out of memory. */
static int pass(const double *src, double *dst, double mu, long m, long i0, long i1,
                int levels, int threads, Compensated *acc)
{
    long nchunks = (i1 - i0 + CHUNK - 1) / CHUNK;
    double *part = malloc(sizeof(double) * (size_t)(levels * nchunks));
    if (!part) return -1;
    Share share[MAX_THREADS];
    long half = threads > 1 ? nchunks / 2 : 0;
    share[0] = (Share){src, dst, NULL, mu, m, i0, i1, 0, nchunks, 0, 0, nchunks, levels, part};
    pthread_t thread;
    int spawned = 0;
    double *side = NULL;
    long side_chunks = 0;
    if (half > 0) {
        share[0].c1 = half;
        share[1] = share[0];
        share[1].c0 = half;
        share[1].c1 = nchunks;
        if (dst && dst == src) {  /* the first share reads up to (2^levels - 1) m ahead */
            long ahead = ((1L << levels) - 1) * m;
            side_chunks = (ahead + CHUNK - 1) / CHUNK;
            if (side_chunks > nchunks - half) side_chunks = nchunks - half;
            side = malloc(sizeof(double) * (size_t)(side_chunks * CHUNK));
            if (!side) {
                free(part);
                return -1;
            }
            share[1].side = side;
            share[1].c_side = half;
            share[1].c_side_end = half + side_chunks;
        }
        spawned = pthread_create(&thread, NULL, run_share, &share[1]) == 0;
    }
    run_share(&share[0]);
    if (half > 0 && spawned)
        pthread_join(thread, NULL);
    else if (half > 0)
        run_share(&share[1]);  /* no thread: the same chunks, the same sums */
    if (side) {
        long start = i0 + half * CHUNK;
        long stop = start + side_chunks * CHUNK < i1 ? start + side_chunks * CHUNK : i1;
        memcpy(dst + start, side, sizeof(double) * (size_t)(stop - start));
        free(side);
    }
    for (int l = 0; l < levels; l++)
        for (long c = 0; c < nchunks; c++) neumaier_add(&acc[l], part[l * nchunks + c]);
    free(part);
    return 0;
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
static int octave(const double *y, long n, double mu, int levels, int threads, double *sums)
{
    Compensated acc[MAX_LEVELS] = {{0.0, 0.0}};
    double *work = NULL;
    const double *src = y;
    double shift = mu;
    long m = 1;
    for (int first = 0; first < levels; first += GROUP) {
        int group = levels - first < GROUP ? levels - first : GROUP;
        int last = first + group == levels;
        if (!last && !work && !(work = work_array(n))) return -1;
        /* level l of the group has terms i <= n - 2^(l+1) m; the group's S_{2^group m}
         * (the next group's input) is needed for i <= n - 2^group m: the full-group span */
        long done = 0;
        for (int l = group; l >= 1; l--) {
            long end = n - (1L << l) * m + 1;
            if (end > done) {
                double *dst = l == group && !last ? work : NULL;
                if (pass(src, dst, shift, m, done, end, l, threads, acc + first) != 0) {
                    free(work);
                    return -1;
                }
                done = end;
            }
        }
        src = work;
        shift = 0.0;
        m <<= group;
    }
    free(work);
    for (int l = 0; l < levels; l++) sums[l] = acc[l].sum + acc[l].compensation;
    return 0;
}

static PyObject *octave_sums(PyObject *self, PyObject *args)
{
    PyObject *data;
    double mu;
    int levels, threads;
    (void)self;
    if (!PyArg_ParseTuple(args, "Odii", &data, &mu, &levels, &threads)) return NULL;
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
    } else if (threads < 1 || threads > MAX_THREADS) {
        PyErr_Format(PyExc_ValueError, "threads must be 1..%d, got %d", MAX_THREADS, threads);
    } else {
        double sums[MAX_LEVELS];
        int status;
        Py_BEGIN_ALLOW_THREADS
        status = octave((const double *)view.buf, n, mu, levels, threads, sums);
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
     "octave_sums(y, mean, levels, threads) -> list of float\n\n"
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
