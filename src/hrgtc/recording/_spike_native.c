/* The robust spike filter's loops (hrgtc.recording.spikes), one channel per call.
 *
 * Private to hrgtc.recording._spike_kernel (its Python side); built by `pip install -e .`
 * (setup.py). Why C and not numba: a command that filters spikes paid numba's import,
 * its first-call start and the loading of the cached kernel (~0.6 s) for a pass of a few
 * tens of ms (docs/architecture.md, "The native kernels").
 *
 * What it computes is the numba kernel it replaces, bit for bit (tests/recording/
 * test_spike_native.py compares the two): the contiguous segments (a step beyond
 * gap_periods median periods, or not finite, cuts); per segment of at least 3 samples the
 * second differences x[i] - (x[i-1] + x[i+1]) / 2, the window_s windows (runs of one value
 * of floor((t - min t) / window_s)), each window's sigma_MAD (the median of its absolute
 * finite second differences; a window with fewer than min_window of them takes its
 * segment's) and the threshold max(k sigma_MAD, floor); then the test of each sample:
 * SPIKE (a single-sample spike) or ACROSS (motion across the sample).
 *
 * The medians are order statistics: any correct selection picks the same values, and
 * the mean of the two middle values of an even count is (a + b) / 2 as numpy computes
 * it. They are taken of absolute values and positive steps, so no zero's sign differs.
 * setup.py passes -ffp-contract=off: no product is fused into an add.
 */
#include "../_buffers.h"
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#define SPIKE 0
#define ACROSS 1

/* The AVX2 clone where the CPU has it (picked at load time), SSE2 otherwise: floor() is
 * then one instruction instead of SSE2's sequence (the value is the same; floor is exact).
 * No FMA is enabled in either, and setup.py passes -ffp-contract=off. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__linux__)
#define CLONES __attribute__((target_clones("avx2", "default")))
#else
#define CLONES
#endif

/* A window of more values than this has its median bracketed by a sorted sample of about
 * SAMPLE values, MARGIN sample ranks either side of the middle (about 2.5 standard errors
 * of a sample quantile); a smaller one is selected directly. */
#define SAMPLE 64
#define MARGIN 10

typedef struct {
    double k, floor, window_s, gap_periods, tolerance;
    long min_window;
    double mad_to_sigma, second_diff;
} Rule;

static inline void swap(double *a, long i, long j)
{
    double v = a[i];
    a[i] = a[j];
    a[j] = v;
}

/* The k-th smallest of a[:n] (no NaN), a reordered so that every value after index k is
 * at least it (Hoare's partition, median-of-three pivot: a run of equal values, as a
 * quantised channel gives, splits in the middle). */
static double select_kth(double *a, long n, long k)
{
    long lo = 0, hi = n - 1;
    while (hi > lo) {
        long mid = (lo + hi) >> 1;
        if (a[mid] < a[lo]) swap(a, mid, lo);
        if (a[hi] < a[lo]) swap(a, hi, lo);
        if (a[hi] < a[mid]) swap(a, hi, mid);
        double pivot = a[mid];
        long i = lo, j = hi;
        while (i <= j) {
            while (a[i] < pivot) i++;
            while (pivot < a[j]) j--;
            if (i <= j) {
                swap(a, i, j);
                i++;
                j--;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return a[k];
    }
    return a[k];
}

/* np.median(a[:n]) of n >= 1 values (no NaN; a reordered). */
static double plain_median(double *a, long n)
{
    long half = n >> 1;
    if (n & 1) return select_kth(a, n, half);
    double low = select_kth(a, n, half - 1);
    double high = a[half];
    for (long i = half + 1; i < n; i++)
        if (a[i] < high) high = a[i];
    return (low + high) / 2;
}

static int by_value(const void *p, const void *q)
{
    double a = *(const double *)p, b = *(const double *)q;
    return (a > b) - (a < b);
}

/* What one pass counted against a bracket [lo, hi] of the middle ranks: the values below
 * it, equal to lo, equal to hi (if hi != lo), and those strictly inside (kept, in order of
 * the pass, in `between`). */
typedef struct {
    double lo, hi;
    long below, equal_lo, equal_hi, kept;
} Bracket;

/* The median of `count` values from what the pass counted into *out (`between`
 * reordered); 0 if the middle ranks are not inside the bracket. The lower middle value is
 * selected among the kept ones; the upper one, when it is the next rank among them, is
 * their smallest after it (the selection left every value after it at least as large). */
static int bracket_median(const Bracket *b, double *between, long count, double *out)
{
    long k_lo = (count - 1) / 2, k_hi = count / 2;
    long r_lo = k_lo - b->below, r_hi = k_hi - b->below;
    if (count < 1 || r_lo < 0 || r_hi >= b->equal_lo + b->kept + b->equal_hi) return 0;
    double picked[2];
    long selected = -1;
    for (int j = 0; j < (k_lo == k_hi ? 1 : 2); j++) {
        long r = j == 0 ? r_lo : r_hi;
        if (r < b->equal_lo) {
            picked[j] = b->lo;
        } else if (r < b->equal_lo + b->kept && selected >= 0) {
            double least = between[selected + 1];
            for (long i = selected + 2; i < b->kept; i++)
                least = between[i] < least ? between[i] : least;
            picked[j] = least;
        } else if (r < b->equal_lo + b->kept) {
            selected = r - b->equal_lo;
            picked[j] = select_kth(between, b->kept, selected);
        } else {
            picked[j] = b->hi;
        }
    }
    *out = k_lo == k_hi ? picked[0] : (picked[0] + picked[1]) / 2;
    return 1;
}

/* np.median(a[:n]) of n >= 1 values (no NaN; a reordered), mostly without branches: a
 * sorted sample of about SAMPLE values brackets the middle ranks, one pass counts what
 * lies below the bracket and keeps what lies inside it (in `between`, room for n), and the
 * middle values are selected among those (among all of them if the bracket missed). A
 * selection on random values mispredicts a branch at every other comparison; the pass
 * does not. */
static double median(double *a, long n, double *between)
{
    if (n <= 4 * SAMPLE) return plain_median(a, n);
    double sample[2 * SAMPLE + 2];
    long stride = n / SAMPLE, size = 0;
    for (long i = 0; i < n; i += stride) sample[size++] = a[i];
    qsort(sample, (size_t)size, sizeof(double), by_value);
    long k_lo = (n - 1) / 2, k_hi = n / 2;
    long i_lo = k_lo * size / n - MARGIN, i_hi = k_hi * size / n + MARGIN;
    double lo = sample[i_lo > 0 ? i_lo : 0];
    double hi = sample[i_hi < size - 1 ? i_hi : size - 1];
    long below = 0, equal_lo = 0, equal_hi = 0, kept = 0;
    const long distinct = hi != lo;
    for (long i = 0; i < n; i++) {
        double v = a[i];
        below += v < lo;
        equal_lo += v == lo;
        equal_hi += (v == hi) & distinct;
        between[kept] = v;
        kept += (lo < v) & (v < hi);
    }
    Bracket bracket = {lo, hi, below, equal_lo, equal_hi, kept};
    double middle;
    return bracket_median(&bracket, between, n, &middle) ? middle : plain_median(a, n);
}

/* Is step i of t (t[i + 1] - t[i]) positive and finite? */
static inline int positive_step(const double *t, long i, double *step)
{
    *step = t[i + 1] - t[i];
    return isfinite(*step) && *step > 0;
}

/* The median of the positive finite steps of t[:n] (n >= 2) into *out; 0 if there is
 * none. For a long record, without writing the steps out: a sample of the steps at a
 * regular stride brackets the middle ranks, one pass over t counts the steps below the
 * bracket and keeps those inside it (in `between`; a regular clock has few), and the middle
 * values are selected among those. Otherwise (a short record, or a bracket that missed)
 * the steps are gathered into `work` and their median taken. Both have room for n. */
static int steps_median(const double *t, long n, double *work, double *between, double *out)
{
    double step, sample[2 * SAMPLE + 2];
    long size = 0, stride = (n - 1) / SAMPLE;
    if (n - 1 > 4 * SAMPLE) {
        for (long i = 0; i < n - 1 && size < 2 * SAMPLE + 2; i += stride)
            if (positive_step(t, i, &step)) sample[size++] = step;
    }
    if (size > 2 * MARGIN) {
        qsort(sample, (size_t)size, sizeof(double), by_value);
        double lo = sample[(size - 1) / 2 - MARGIN], hi = sample[size / 2 + MARGIN];
        long count = 0, below = 0, equal_lo = 0, equal_hi = 0, kept = 0;
        const long distinct = hi != lo;
        for (long i = 0; i < n - 1; i++) {
            double v = t[i + 1] - t[i];
            long valid = isfinite(v) && v > 0;
            count += valid;
            below += valid & (v < lo);
            equal_lo += v == lo;
            equal_hi += (v == hi) & distinct;
            between[kept] = v;
            kept += (lo < v) & (v < hi);
        }
        Bracket bracket = {lo, hi, below, equal_lo, equal_hi, kept};
        if (bracket_median(&bracket, between, count, out)) return 1;
    }
    long count = 0;
    for (long i = 0; i < n - 1; i++)
        if (positive_step(t, i, &step)) work[count++] = step;
    if (!count) return 0;
    *out = median(work, count, between);
    return 1;
}

/* End (exclusive) of each contiguous segment of t[:n] into stops (room for n + 1), their
 * count returned: a step that is not <= gap_periods * median(positive finite steps) *
 * tolerance starts a new segment; without a positive step the whole is one segment.
 * `work` and `between` have room for n values. */
static long segment_stops(const double *t, long n, const Rule *rule, long *stops,
                          double *work, double *between)
{
    if (n < 2) {
        if (n) stops[0] = n;
        return n;
    }
    double middle;
    long s = 0;
    if (steps_median(t, n, work, between, &middle)) {
        double limit = rule->gap_periods * middle * rule->tolerance;
        for (long i = 0; i < n - 1; i++)
            if (!(t[i + 1] - t[i] <= limit)) stops[s++] = i + 1;
    }
    stops[s++] = n;
    return s;
}

/* x[i] - (x[i-1] + x[i+1]) / 2; at a segment's edges, that of the next sample in. */
static inline double second(const double *x, long i, long n)
{
    long j = i < 1 ? 1 : i;
    j = j > n - 2 ? n - 2 : j;
    return x[j] - 0.5 * (x[j - 1] + x[j + 1]);
}

/* The test `mode` of sample i of a segment of n >= 3 samples, threshold q. */
static inline int test(const double *x, long i, long n, double q, int mode)
{
    if (mode == SPIKE) {
        if (i == 0) /* away from both of the next two samples, which agree */
            return (fabs(x[1] - x[0]) > q) & (fabs(x[0] - x[2]) > q) &
                   (fabs(x[2] - x[1]) <= q);
        if (i == n - 1)
            return (fabs(x[n - 1] - x[n - 2]) > q) & (fabs(x[n - 1] - x[n - 3]) > q) &
                   (fabs(x[n - 2] - x[n - 3]) <= q);
        return (fabs(x[i] - x[i - 1]) > q) & (fabs(x[i + 1] - x[i]) > q) &
               (fabs(second(x, i, n)) > q) & (fabs(x[i + 1] - x[i - 1]) <= q);
    }
    if (i == 0 || i == n - 1) return 0.0 > q; /* the edges: never for a threshold >= 0 */
    double across = fabs(x[i + 1] - x[i - 1]);
    if (n >= 5 && 2 <= i && i < n - 2) {
        double wide = fabs(x[i + 2] - x[i - 2]);
        if (across != across || wide != wide) /* np.maximum: NaN if either is NaN */
            across = NAN;
        else if (wide > across)
            across = wide;
    }
    return across > q;
}

/* The samples of a..b (in a segment of n >= 3) whose second difference is x[i]'s own,
 * [*lo, *hi): all but the segment's first and last. */
static inline void interior(long a, long b, long n, long *lo, long *hi)
{
    *lo = a < 1 ? 1 : a;
    *hi = b > n - 1 ? n - 1 : b;
    if (*hi < *lo) *hi = *lo;
}

/* The absolute finite second differences of samples a..b into work, their count
 * returned. The interior is one straight loop (vectorised) that also counts the finite
 * ones; only a window with a value that is not goes through the compacting loop. */
static long window_seconds(const double *x, long a, long b, long n, double *work)
{
    long lo, hi, m = 0;
    interior(a, b, n, &lo, &hi);
    if (a == 0) {
        double d = second(x, 0, n);
        work[m] = fabs(d);
        m += isfinite(d) != 0;
    }
    long finite = 0;
    double *into = work + m;
    for (long i = lo; i < hi; i++) {
        double v = fabs(x[i] - 0.5 * (x[i - 1] + x[i + 1]));
        into[i - lo] = v;
        finite += v <= DBL_MAX;
    }
    if (finite == hi - lo) {
        m += hi - lo;
    } else {
        for (long i = lo; i < hi; i++) {
            double d = x[i] - 0.5 * (x[i - 1] + x[i + 1]);
            work[m] = fabs(d);
            m += isfinite(d) != 0;
        }
    }
    if (b == n) {
        double d = second(x, n - 1, n);
        work[m] = fabs(d);
        m += isfinite(d) != 0;
    }
    return m;
}

/* The test `mode` of samples a..b of a segment of n >= 3 samples, threshold q, into out:
 * test() at the segment's edges, its interior cases in straight loops. ACROSS: NaN if
 * either distance is NaN (np.maximum), so the larger beyond q is both not NaN and one of
 * them beyond q. */
static void window_tests(const double *x, long a, long b, long n, double q, int mode,
                         uint8_t *out)
{
    long lo, hi;
    interior(a, b, n, &lo, &hi);
    if (a == 0) out[0] = (uint8_t)test(x, 0, n, q, mode);
    if (mode == SPIKE) {
        for (long i = lo; i < hi; i++)
            out[i] = (uint8_t)((fabs(x[i] - x[i - 1]) > q) & (fabs(x[i + 1] - x[i]) > q) &
                               (fabs(x[i] - 0.5 * (x[i - 1] + x[i + 1])) > q) &
                               (fabs(x[i + 1] - x[i - 1]) <= q));
    } else {
        long wide_lo = lo > 2 ? lo : 2, wide_hi = hi < n - 2 ? hi : n - 2;
        if (n < 5 || wide_hi < wide_lo) wide_lo = wide_hi = hi;
        for (long i = lo; i < wide_lo; i++) out[i] = (uint8_t)test(x, i, n, q, mode);
        for (long i = wide_lo; i < wide_hi; i++) {
            double across = fabs(x[i + 1] - x[i - 1]), wide = fabs(x[i + 2] - x[i - 2]);
            out[i] = (uint8_t)((across == across) & (wide == wide) &
                               ((across > q) | (wide > q)));
        }
        for (long i = wide_hi; i < hi; i++) out[i] = (uint8_t)test(x, i, n, q, mode);
    }
    if (b == n) out[n - 1] = (uint8_t)test(x, n - 1, n, q, mode);
}

/* sigma_MAD of the segment x[:n]'s absolute finite second differences (0 without one). */
static double segment_sigma(const double *x, long n, const Rule *rule, double *work,
                            double *between)
{
    long count = 0;
    for (long i = 0; i < n; i++) {
        double d = second(x, i, n);
        work[count] = fabs(d);
        count += isfinite(d) != 0;
    }
    if (!count) return 0.0;
    return rule->mad_to_sigma * median(work, count, between) / rule->second_diff;
}

/* The window origin: the smallest time that is not NaN (0 without a finite one). */
static double window_origin(const double *t, long n)
{
    int any_finite = 0;
    double origin = INFINITY;
    for (long i = 0; i < n; i++) {
        double v = t[i];
        if (isfinite(v)) any_finite = 1;
        if (v < origin) origin = v;
    }
    return any_finite ? origin : 0.0;
}

/* The test `mode` of every sample of one segment (t, x)[:n], n >= 3, into out: window by
 * window, the window's sigma_MAD (the segment's when it has fewer than min_window finite
 * second differences), the threshold max(k sigma_MAD, floor), the test of each sample. */
CLONES static void segment_tests(const double *t, const double *x, long n,
                                 const Rule *rule, int mode, uint8_t *out, double *work,
                                 double *between)
{
    const double origin = window_origin(t, n);
    double whole = -1.0; /* the segment's sigma, computed when a window needs it */
    double previous = floor((t[0] - origin) / rule->window_s);
    long a = 0;
    for (long b = 1; b <= n; b++) {
        if (b < n) {
            double block = floor((t[b] - origin) / rule->window_s);
            double step = block - previous;
            previous = block;
            if (!(step != 0.0)) continue;
        }
        long m = window_seconds(x, a, b, n, work);
        double sigma;
        if (m >= rule->min_window) {
            sigma = rule->mad_to_sigma * median(work, m, between) / rule->second_diff;
        } else {
            if (whole < 0.0) whole = segment_sigma(x, n, rule, work, between);
            sigma = whole;
        }
        double value = rule->k * sigma, threshold;
        if (value != value || rule->floor != rule->floor) /* np.maximum: NaN if either is */
            threshold = NAN;
        else
            threshold = value >= rule->floor ? value : rule->floor;
        window_tests(x, a, b, n, threshold, mode, out);
        a = b;
    }
}

/* The test `mode` of a whole channel into out (zeroed by the caller); -1 without memory. */
static int channel_test(const double *t, const double *x, long n, const Rule *rule, int mode,
                        uint8_t *out)
{
    long *stops = malloc(sizeof(long) * (size_t)(n + 1));
    double *work = malloc(sizeof(double) * (size_t)(n + 1));
    double *between = malloc(sizeof(double) * (size_t)(n + 1));
    int status = -1;
    if (stops && work && between) {
        long count = segment_stops(t, n, rule, stops, work, between), start = 0;
        for (long s = 0; s < count; s++) {
            long stop = stops[s];
            if (stop - start >= 3)
                segment_tests(t + start, x + start, stop - start, rule, mode, out + start,
                              work, between);
            start = stop;
        }
        status = 0;
    }
    free(stops);
    free(work);
    free(between);
    return status;
}

static PyObject *py_channel_test(PyObject *self, PyObject *args)
{
    PyObject *objects[3];
    Rule rule;
    int mode;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO(dddddldd)i", &objects[0], &objects[1], &objects[2],
                          &rule.k, &rule.floor, &rule.window_s, &rule.gap_periods,
                          &rule.tolerance, &rule.min_window, &rule.mad_to_sigma,
                          &rule.second_diff, &mode))
        return NULL;
    if (mode != SPIKE && mode != ACROSS) {
        PyErr_Format(PyExc_ValueError, "mode must be 0 (spike) or 1 (across), got %d", mode);
        return NULL;
    }
    if (rule.min_window < 1) {
        PyErr_Format(PyExc_ValueError, "min_window must be at least 1, got %ld",
                     rule.min_window);
        return NULL;
    }
    Py_buffer views[3];
    if (hrgtc_vector(objects[0], &views[0], HRGTC_F64, 8, 0, "time_s (float64)")) return NULL;
    if (hrgtc_vector(objects[1], &views[1], HRGTC_F64, 8, 0, "values (float64)")) {
        hrgtc_release(views, 1);
        return NULL;
    }
    if (hrgtc_vector(objects[2], &views[2], HRGTC_BOOL, 1, 1, "out (bool)")) {
        hrgtc_release(views, 2);
        return NULL;
    }
    long n = (long)hrgtc_len(&views[0]);
    if (hrgtc_len(&views[1]) != n || hrgtc_len(&views[2]) != n) {
        PyErr_Format(PyExc_ValueError, "time_s, values and out must have one length, got "
                     "%zd, %zd and %zd", hrgtc_len(&views[0]), hrgtc_len(&views[1]),
                     hrgtc_len(&views[2]));
        hrgtc_release(views, 3);
        return NULL;
    }
    int status;
    Py_BEGIN_ALLOW_THREADS
    status = channel_test(views[0].buf, views[1].buf, n, &rule, mode, views[2].buf);
    Py_END_ALLOW_THREADS
    hrgtc_release(views, 3);
    if (status != 0) return PyErr_NoMemory();
    Py_RETURN_NONE;
}

static PyMethodDef methods[] = {
    {"channel_test", py_channel_test, METH_VARARGS,
     "channel_test(time_s, values, out, rule, mode) -> None\n\n"
     "The spike filter's test `mode` (0 spike, 1 across) of one channel into `out` (bool,\n"
     "zeroed); time_s and values contiguous 1-D float64 of one length, rule the 8 fields\n"
     "of hrgtc.recording._spike_kernel.SpikeRule."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_spike_native",
    "The spike filter's loops (see _spike_native.c).", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__spike_native(void) { return PyModule_Create(&module); }
