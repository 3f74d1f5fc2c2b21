/* The at-rest detector's loops (hrgtc.recording.motion), in C.
 *
 * Private to hrgtc.recording (_motion_kernel.py wraps it: it allocates the outputs, this
 * fills them); built by `pip install -e .` (setup.py). Why C and not numba: a command
 * that runs the detector spent ~0.4 s loading its eight cached numba dispatchers, as much
 * as the loops (docs/architecture.md, "The native at-rest detector").
 *
 * Each kernel is the numba kernel it replaces, line for line (the numba text is kept in
 * tests/recording/_motion_numba_reference.py; test_motion_native.py compares the two bit
 * for bit). The medians, sorts and partitions are numba's own algorithms (numba 0.68's
 * np.median: quickselect with a median-of-three pivot and `<`; np.sort: its quicksort
 * with NaN last, insertion sort under 16 values; np.partition: the NaN-aware
 * quickselect; np.min: the first NaN or the first smallest), so even the sign of a zero
 * median and the place of a NaN are numba's. No fast-math, no FMA contraction (setup.py
 * passes -ffp-contract=off): every product and sum is rounded as written.
 *
 * Parts: _motion_order.h (numba's order statistics, the bracketing median),
 * _motion_segment.h (one segment's tests, the guards), _motion_digest.h (compensate's
 * digest of its rows); this file: the first differences and the Python boundary.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef Py_ssize_t idx;

#include "_motion_order.h"

/* ------------------------------------------------------------- first differences */

enum { FORWARD = 0, INSIDE = 1, DEVIATION = 2, INSIDE_FORWARD = 3 };

static inline int valid(const double *x, const uint8_t *breaks, idx i, int mode)
{
    int inside = (mode == FORWARD) | !breaks[i];
    int forward = ((mode != FORWARD) & (mode != INSIDE_FORWARD)) | (x[i + 1] - x[i] > 0);
    return inside & forward;
}

static inline double value(const double *x, idx i, int mode, double centre)
{
    double d = x[i + 1] - x[i];
    return mode == DEVIATION ? fabs(d - centre) : d;
}

static idx count_valid(const double *x, const uint8_t *breaks, idx n, int mode)
{
    idx count = 0;
    for (idx i = 0; i < n; i++) count += valid(x, breaks, i, mode);
    return count;
}

/* the sample of difference_sample: returns how many were written to `sample` */
static idx sample_differences(const double *x, const uint8_t *breaks, idx n, int mode,
                              double centre, idx stride, double *sample)
{
    idx s = 0;
    for (idx i = 0; i < n; i += stride)
        if (valid(x, breaks, i, mode)) sample[s++] = value(x, i, mode, centre);
    return s;
}

/* one mode's loop: `mode` a constant in each call of bracket_differences, so the
 * selection compiles to selects (no branch) and the loop is specialised */
static inline __attribute__((always_inline)) void bracket_mode(
    const double *x, const uint8_t *breaks, idx n, const int mode, double centre, double lo,
    double hi, idx counts[4], double *inside)
{
    idx below = 0, equal_lo = 0, equal_hi = 0, kept = 0;
    const int distinct = hi != lo;
    for (idx i = 0; i < n; i++) {
        int ok = valid(x, breaks, i, mode);
        double v = value(x, i, mode, centre);
        below += ok & (v < lo);
        equal_lo += ok & (v == lo);
        equal_hi += ok & (v == hi) & distinct;
        inside[kept] = v;
        kept += ok & (lo < v) & (v < hi);
    }
    counts[0] = below;
    counts[1] = equal_lo;
    counts[2] = kept;
    counts[3] = equal_hi;
}

static void bracket_differences(const double *x, const uint8_t *breaks, idx n, int mode,
                                double centre, double lo, double hi, idx counts[4],
                                double *inside)
{
    switch (mode) {
    case FORWARD: bracket_mode(x, breaks, n, FORWARD, centre, lo, hi, counts, inside); break;
    case INSIDE: bracket_mode(x, breaks, n, INSIDE, centre, lo, hi, counts, inside); break;
    case DEVIATION: bracket_mode(x, breaks, n, DEVIATION, centre, lo, hi, counts, inside); break;
    default: bracket_mode(x, breaks, n, INSIDE_FORWARD, centre, lo, hi, counts, inside);
    }
}

static idx gather_differences(const double *x, const uint8_t *breaks, idx n, int mode,
                              double centre, idx count, double *out)
{
    idx k = 0;
    for (idx i = 0; i < n; i++)
        if (valid(x, breaks, i, mode)) {
            if (k < count) out[k] = value(x, i, mode, centre);
            k++;
        }
    return k;
}

#include "_motion_segment.h"

/* ------------------------------------------------------------- the Python boundary */

enum { F64 = 'd', I64 = 'q', BOOL = '?' };

/* A C-contiguous 1-D buffer of `kind` (float64, int64 or bool), writable if asked;
 * TypeError naming the argument otherwise. */
static int take(PyObject *obj, Py_buffer *view, int kind, int writable, const char *name)
{
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, view, flags) != 0) {
        PyErr_Clear();
        PyErr_Format(PyExc_TypeError, "%s must be a contiguous 1-D %s%s array", name,
                     kind == F64 ? "float64" : kind == I64 ? "int64" : "bool",
                     writable ? " (writable)" : "");
        return -1;
    }
    const char *f = view->format ? view->format : "B";
    if (*f == '@' || *f == '=' || *f == '<') f++;
    char c = f[0] && !f[1] ? f[0] : 0;
    int ok = view->ndim == 1 &&
             (kind == F64 ? c == 'd' && view->itemsize == 8
              : kind == I64 ? (c == 'q' || c == 'l') && view->itemsize == 8
                            : c == '?' && view->itemsize == 1);
    if (!ok) {
        PyBuffer_Release(view);
        PyErr_Format(PyExc_TypeError, "%s must be a contiguous 1-D %s array", name,
                     kind == F64 ? "float64" : kind == I64 ? "int64" : "bool");
        return -1;
    }
    return 0;
}

#define MAX_VIEWS 12
typedef struct {
    Py_buffer views[MAX_VIEWS];
    int count;
} Views;

/* The next argument's buffer (NULL after an error: the views taken so far released) */
static void *arg(Views *v, PyObject *obj, int kind, int writable, const char *name, idx *size)
{
    Py_buffer *view = &v->views[v->count];
    if (take(obj, view, kind, writable, name) != 0) {
        while (v->count > 0) PyBuffer_Release(&v->views[--v->count]);
        return NULL;
    }
    v->count++;
    *size = view->len / view->itemsize;
    return view->buf;
}

static PyObject *done(Views *v, PyObject *result)
{
    while (v->count > 0) PyBuffer_Release(&v->views[--v->count]);
    return result;
}

static PyObject *fail(Views *v, PyObject *type, const char *message)
{
    PyErr_SetString(type, message);
    return done(v, NULL);
}

/* x and breaks of the difference kernels: n = x.size - 1 differences, breaks >= n */
static int differences(Views *v, PyObject *x_obj, PyObject *b_obj, int mode,
                       const double **x, const uint8_t **breaks, idx *n)
{
    idx size, nb;
    if (!(*x = arg(v, x_obj, F64, 0, "x", &size))) return -1;
    if (!(*breaks = arg(v, b_obj, BOOL, 0, "breaks", &nb))) return -1;
    *n = size > 0 ? size - 1 : 0;
    if (nb < *n || mode < FORWARD || mode > INSIDE_FORWARD) {
        PyErr_SetString(PyExc_ValueError, "breaks needs x.size - 1 values and mode 0-3");
        done(v, NULL);
        return -1;
    }
    return 0;
}

static PyObject *py_median(PyObject *self, PyObject *args)
{
    PyObject *obj;
    Views v = {.count = 0};
    idx n;
    (void)self;
    if (!PyArg_ParseTuple(args, "O", &obj)) return NULL;
    const double *values = arg(&v, obj, F64, 0, "values", &n);
    if (!values) return NULL;
    double *work = malloc(sizeof(double) * (size_t)(n > 0 ? n : 1)), out = 0.0;
    int status = -1;
    if (work) {
        Py_BEGIN_ALLOW_THREADS
        status = long_median(values, n, work, &out);
        Py_END_ALLOW_THREADS
    }
    free(work);
    if (status != 0) return done(&v, PyErr_NoMemory());
    return done(&v, PyFloat_FromDouble(out));
}

static PyObject *py_difference_sample(PyObject *self, PyObject *args)
{
    PyObject *x_obj, *b_obj, *s_obj;
    int mode;
    double centre;
    Py_ssize_t stride;
    Views v = {.count = 0};
    const double *x;
    const uint8_t *breaks;
    idx n, size, count, s;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOidnO", &x_obj, &b_obj, &mode, &centre, &stride, &s_obj))
        return NULL;
    if (differences(&v, x_obj, b_obj, mode, &x, &breaks, &n) != 0) return NULL;
    double *sample = arg(&v, s_obj, F64, 1, "sample", &size);
    if (!sample) return NULL;
    if (stride < 1 || size < n / stride + 1) return fail(&v, PyExc_ValueError,
                                                          "sample needs n // stride + 1 values");
    Py_BEGIN_ALLOW_THREADS
    count = count_valid(x, breaks, n, mode);
    s = sample_differences(x, breaks, n, mode, centre, stride, sample);
    Py_END_ALLOW_THREADS
    return done(&v, Py_BuildValue("nn", count, s));
}

static PyObject *py_bracket(PyObject *self, PyObject *args)
{
    PyObject *x_obj, *b_obj, *i_obj;
    int mode;
    double centre, lo, hi;
    Views v = {.count = 0};
    const double *x;
    const uint8_t *breaks;
    idx n, size, counts[4];
    (void)self;
    if (!PyArg_ParseTuple(args, "OOidddO", &x_obj, &b_obj, &mode, &centre, &lo, &hi, &i_obj))
        return NULL;
    if (differences(&v, x_obj, b_obj, mode, &x, &breaks, &n) != 0) return NULL;
    double *inside = arg(&v, i_obj, F64, 1, "inside", &size);
    if (!inside) return NULL;
    if (size < n) return fail(&v, PyExc_ValueError, "inside needs x.size - 1 values");
    Py_BEGIN_ALLOW_THREADS
    bracket_differences(x, breaks, n, mode, centre, lo, hi, counts, inside);
    Py_END_ALLOW_THREADS
    return done(&v, Py_BuildValue("nnnn", counts[0], counts[1], counts[2], counts[3]));
}

static PyObject *py_gather(PyObject *self, PyObject *args)
{
    PyObject *x_obj, *b_obj, *o_obj;
    int mode;
    double centre;
    Views v = {.count = 0};
    const double *x;
    const uint8_t *breaks;
    idx n, size, found;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOidO", &x_obj, &b_obj, &mode, &centre, &o_obj)) return NULL;
    if (differences(&v, x_obj, b_obj, mode, &x, &breaks, &n) != 0) return NULL;
    double *out = arg(&v, o_obj, F64, 1, "out", &size);
    if (!out) return NULL;
    Py_BEGIN_ALLOW_THREADS
    found = gather_differences(x, breaks, n, mode, centre, size, out);
    Py_END_ALLOW_THREADS
    if (found != size) {
        PyErr_Format(PyExc_ValueError, "gather: %zd differences selected, out holds %zd",
                     found, size);
        return done(&v, NULL);
    }
    return done(&v, Py_NewRef(Py_None));
}

static PyObject *py_first_not_finite(PyObject *self, PyObject *args)
{
    PyObject *obj;
    Views v = {.count = 0};
    idx n, row = -1;
    (void)self;
    if (!PyArg_ParseTuple(args, "O", &obj)) return NULL;
    const double *values = arg(&v, obj, F64, 0, "values", &n);
    if (!values) return NULL;
    Py_BEGIN_ALLOW_THREADS
    for (idx i = 0; i < n; i++)
        if (!isfinite(values[i])) {
            row = i;
            break;
        }
    Py_END_ALLOW_THREADS
    return done(&v, PyLong_FromSsize_t(row));
}

/* find_breaks (out: bool) and steps_over (out: int64, returns how many) */
static PyObject *py_steps(PyObject *self, PyObject *args, int breaks)
{
    PyObject *t_obj, *o_obj;
    double limit;
    Views v = {.count = 0};
    idx n, size, kept = 0;
    (void)self;
    if (!PyArg_ParseTuple(args, "OdO", &t_obj, &limit, &o_obj)) return NULL;
    const double *t = arg(&v, t_obj, F64, 0, "time_s", &n);
    if (!t) return NULL;
    void *out = arg(&v, o_obj, breaks ? BOOL : I64, 1, "out", &size);
    if (!out) return NULL;
    if (size < (n > 1 ? n - 1 : 0)) return fail(&v, PyExc_ValueError,
                                                "out needs time_s.size - 1 values");
    Py_BEGIN_ALLOW_THREADS
    for (idx i = 0; i + 1 < n; i++) {
        double step = t[i + 1] - t[i];
        if (breaks) {
            ((uint8_t *)out)[i] = (step > limit) | (step <= 0);
        } else {
            ((int64_t *)out)[kept] = i;
            kept += step > limit;
        }
    }
    Py_END_ALLOW_THREADS
    return done(&v, PyLong_FromSsize_t(kept));
}

static PyObject *py_find_breaks(PyObject *self, PyObject *args) { return py_steps(self, args, 1); }
static PyObject *py_steps_over(PyObject *self, PyObject *args) { return py_steps(self, args, 0); }

static PyObject *py_segment_index(PyObject *self, PyObject *args)
{
    PyObject *b_obj, *o_obj;
    Views v = {.count = 0};
    idx n, size;
    (void)self;
    if (!PyArg_ParseTuple(args, "OO", &b_obj, &o_obj)) return NULL;
    const uint8_t *breaks = arg(&v, b_obj, BOOL, 0, "breaks", &n);
    if (!breaks) return NULL;
    int64_t *out = arg(&v, o_obj, I64, 1, "out", &size);
    if (!out) return NULL;
    if (size != n + 1) return fail(&v, PyExc_ValueError, "out needs breaks.size + 1 values");
    int64_t k = 0;
    out[0] = 0;
    for (idx i = 0; i < n; i++) {
        k += breaks[i] != 0;
        out[i + 1] = k;
    }
    return done(&v, Py_NewRef(Py_None));
}

static PyObject *py_segment_tests(PyObject *self, PyObject *args)
{
    PyObject *t_obj, *x_obj, *e_obj, *o_obj[4];
    Tests c;
    Views v = {.count = 0};
    idx m, nt, ne, size;
    uint8_t *out[4];
    static const char *names[4] = {"level", "variance", "clipped", "stepped"};
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO(nnnddddddddnpp)OOOO", &t_obj, &x_obj, &e_obj,
                          &c.baseline_blocks, &c.var_rows, &c.min_run, &c.level_limit,
                          &c.diff_sigma, &c.diff_centre, &c.mad_to_sigma, &c.variance_limit,
                          &c.clip_limit, &c.high, &c.low, &c.clip_samples, &c.sigma_positive,
                          &c.held, &o_obj[0], &o_obj[1], &o_obj[2], &o_obj[3]))
        return NULL;
    const double *t = arg(&v, t_obj, F64, 0, "t", &nt);
    if (!t) return NULL;
    const double *values = arg(&v, x_obj, F64, 0, "values", &m);
    if (!values) return NULL;
    const idx *edges = arg(&v, e_obj, I64, 0, "edges", &ne);
    if (!edges) return NULL;
    for (int k = 0; k < 4; k++) {
        if (!(out[k] = arg(&v, o_obj[k], BOOL, 1, names[k], &size))) return NULL;
        if (size != m) return fail(&v, PyExc_ValueError, "each mask needs values.size values");
    }
    if (nt != m || m < 1) return fail(&v, PyExc_ValueError,
                                      "t and values need the same size, at least 1");
    int ordered = ne >= 2 && edges[0] == 0 && edges[ne - 1] == m;
    for (idx k = 0; ordered && k + 1 < ne; k++) ordered = edges[k] < edges[k + 1];
    if (!ordered) return fail(&v, PyExc_ValueError,
                              "edges must rise strictly from 0 to values.size");
    if (c.baseline_blocks < 1 || c.var_rows < 1 || c.min_run < 1 || c.clip_samples < 1)
        return fail(&v, PyExc_ValueError, "baseline_blocks, var_rows, min_run and "
                                          "clip_samples must be at least 1");
    int status;
    Py_BEGIN_ALLOW_THREADS
    status = segment_tests(t, values, m, edges, ne - 1, &c, out);
    Py_END_ALLOW_THREADS
    if (status != 0) return done(&v, PyErr_NoMemory());
    return done(&v, Py_NewRef(Py_None));
}

static PyObject *py_guard(PyObject *self, PyObject *args)
{
    PyObject *f_obj[4], *a_obj, *b_obj, *m_obj, *g_obj;
    Py_ssize_t after, before;
    Views v = {.count = 0};
    idx n, size, segments, stops_size;
    const uint8_t *found[4];
    static const char *names[4] = {"level", "variance", "clipped", "accel"};
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOOOnnOO", &f_obj[0], &f_obj[1], &f_obj[2], &f_obj[3],
                          &a_obj, &b_obj, &after, &before, &m_obj, &g_obj))
        return NULL;
    uint8_t *moving = arg(&v, m_obj, BOOL, 1, "moving", &n);
    if (!moving) return NULL;
    uint8_t *guarded = arg(&v, g_obj, BOOL, 1, "guarded", &size);
    if (!guarded) return NULL;
    if (size != n) return fail(&v, PyExc_ValueError, "guarded needs moving.size values");
    for (int k = 0; k < 4; k++) {
        if (!(found[k] = arg(&v, f_obj[k], BOOL, 0, names[k], &size))) return NULL;
        if (size != n) return fail(&v, PyExc_ValueError, "each mask needs moving.size values");
    }
    const idx *starts = arg(&v, a_obj, I64, 0, "starts", &segments);
    if (!starts) return NULL;
    const idx *stops = arg(&v, b_obj, I64, 0, "stops", &stops_size);
    if (!stops) return NULL;
    int ok = stops_size == segments && after >= 0 && before >= 0;
    for (idx k = 0; ok && k < segments; k++)
        ok = 0 <= starts[k] && starts[k] <= stops[k] && stops[k] <= n;
    if (!ok) return fail(&v, PyExc_ValueError, "starts and stops must be segments "
                                               "0 <= start <= stop <= n; after, before >= 0");
    Py_BEGIN_ALLOW_THREADS
    guard(found, starts, stops, segments, after, before, moving, guarded, n);
    Py_END_ALLOW_THREADS
    return done(&v, Py_NewRef(Py_None));
}

static PyObject *py_isolated_runs(PyObject *self, PyObject *args)
{
    PyObject *s_obj, *n_obj, *o_obj;
    Views v = {.count = 0};
    idx n, near_size, out_size;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO", &s_obj, &n_obj, &o_obj)) return NULL;
    const uint8_t *stepped = arg(&v, s_obj, BOOL, 0, "stepped", &n);
    if (!stepped) return NULL;
    const uint8_t *near = arg(&v, n_obj, BOOL, 0, "near", &near_size);
    if (!near) return NULL;
    uint8_t *out = arg(&v, o_obj, BOOL, 1, "out", &out_size);
    if (!out) return NULL;
    if (near_size != n || out_size != n)
        return fail(&v, PyExc_ValueError, "stepped, near and out need the same size");
    Py_BEGIN_ALLOW_THREADS
    isolated_runs(stepped, near, out, n);
    Py_END_ALLOW_THREADS
    return done(&v, Py_NewRef(Py_None));
}

#include "_motion_digest.h"

static PyObject *py_digest_update(PyObject *self, PyObject *args)
{
    PyObject *s_obj, *v_obj;
    Views v = {.count = 0};
    idx ns, n;
    (void)self;
    if (!PyArg_ParseTuple(args, "OO", &s_obj, &v_obj)) return NULL;
    int64_t *state = arg(&v, s_obj, I64, 1, "state", &ns);
    if (!state) return NULL;
    const double *values = arg(&v, v_obj, F64, 0, "values", &n);
    if (!values) return NULL;
    if (ns != 5) return fail(&v, PyExc_ValueError, "state needs 5 int64 values");
    Py_BEGIN_ALLOW_THREADS
    digest_feed((uint64_t *)state, (const uint64_t *)values, n);
    Py_END_ALLOW_THREADS
    return done(&v, Py_NewRef(Py_None));
}

static PyObject *py_digest(PyObject *self, PyObject *args)
{
    PyObject *s_obj;
    Views v = {.count = 0};
    idx ns;
    (void)self;
    if (!PyArg_ParseTuple(args, "O", &s_obj)) return NULL;
    int64_t *state = arg(&v, s_obj, I64, 0, "state", &ns);
    if (!state) return NULL;
    if (ns != 5) return fail(&v, PyExc_ValueError, "state needs 5 int64 values");
    return done(&v, PyLong_FromUnsignedLongLong(digest_final((const uint64_t *)state)));
}

static PyMethodDef methods[] = {
    {"median", py_median, METH_VARARGS, "median(values) -> float (see _motion_kernel.median)"},
    {"difference_sample", py_difference_sample, METH_VARARGS,
     "difference_sample(x, breaks, mode, centre, stride, sample) -> (count, written)"},
    {"bracket", py_bracket, METH_VARARGS,
     "bracket(x, breaks, mode, centre, lo, hi, inside) -> (below, equal_lo, kept, equal_hi)"},
    {"gather", py_gather, METH_VARARGS, "gather(x, breaks, mode, centre, out) -> None"},
    {"first_not_finite", py_first_not_finite, METH_VARARGS, "first_not_finite(values) -> int"},
    {"find_breaks", py_find_breaks, METH_VARARGS, "find_breaks(time_s, gap_s, out) -> int"},
    {"steps_over", py_steps_over, METH_VARARGS, "steps_over(time_s, limit, out) -> kept"},
    {"segment_index", py_segment_index, METH_VARARGS, "segment_index(breaks, out) -> None"},
    {"segment_tests", py_segment_tests, METH_VARARGS,
     "segment_tests(t, values, edges, tests, level, variance, clipped, stepped) -> None"},
    {"guard", py_guard, METH_VARARGS,
     "guard(level, variance, clipped, accel, starts, stops, after, before, moving, "
     "guarded) -> None"},
    {"isolated_runs", py_isolated_runs, METH_VARARGS, "isolated_runs(stepped, near, out)"},
    {"digest_update", py_digest_update, METH_VARARGS,
     "digest_update(state, values): feed float64 values' bits into a digest state (5 int64)"},
    {"digest", py_digest, METH_VARARGS, "digest(state) -> int: the 64-bit digest so far"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_motion_native",
    "The at-rest detector's loops (see _motion_native.c).", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__motion_native(void) { return PyModule_Create(&module); }
