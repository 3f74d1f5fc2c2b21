/* The extended-precision pass of hrgtc.drift.regression.refine, in double-double.
 *
 * Private to hrgtc.drift._extended_kernel (its Python side, which says what is computed
 * and cites the method: Dekker's and Knuth's error-free transformations, accumulated as
 * Ogita, Rump and Oishi's Dot2); built by `pip install -e .` (setup.py). Why C and not
 * numba: `calibrate` paid numba's import, its first-call start and the loading of two
 * cached kernels for a pass of tens of ms (docs/architecture.md, "The native kernels").
 *
 * The statements are those of the numba kernels it replaces, in the same order, so the
 * results are the same bits (tests/drift/test_extended_native.py); the error-free
 * transformations need the rounding as written: -ffp-contract=off (setup.py), no
 * fast-math, so no product is fused into an add and no sum is reassociated.
 */
#include "../_buffers.h"
#include <math.h>
#include <stdlib.h>

#define SPLITTER 134217729.0 /* 2^27 + 1: Veltkamp's splitting constant of float64 */

/* s + e = a + b exactly, s = fl(a + b) (Knuth). */
static inline void two_sum(double a, double b, double *s_out, double *e_out)
{
    double s = a + b;
    double bb = s - a;
    *s_out = s;
    *e_out = (a - (s - bb)) + (b - bb);
}

/* hi + lo = a with hi, lo of at most 26 significant bits each (Veltkamp). */
static inline void split(double a, double *hi_out, double *lo_out)
{
    double c = SPLITTER * a;
    double hi = c - (c - a);
    *hi_out = hi;
    *lo_out = a - hi;
}

/* p + e = a * b exactly, p = fl(a * b), from the splits of a and b (Dekker). */
static inline void two_product(double a, double a_hi, double a_lo, double b, double b_hi,
                               double b_lo, double *p_out, double *e_out)
{
    double p = a * b;
    *p_out = p;
    *e_out = a_lo * b_lo - (((p - a_hi * b_hi) - a_lo * b_hi) - a_hi * b_lo);
}

typedef struct {
    const double *X, *y, *shift, *inverse, *weights; /* weights NULL: unweighted */
    const double *x_hi, *x_lo;
    double *r_hi, *r_lo, *f, *g_hi, *g_lo;
    long n, k;
    int first;
} Pass;

/* Row i of the design into (a_hi, a_lo) and its response into (b_hi, b_lo): a constant
 * column and X's columns shifted (float64 TwoSums) and scaled (powers of two: exact), both
 * times the double-double square root of the row's weight when there are weights. */
static void design_row(const Pass *s, long i, double *a_hi, double *a_lo, double *b_hi,
                       double *b_lo)
{
    const long k = s->k;
    const double *row = s->X + i * k;
    double hi, lo, p, e;
    a_hi[0] = 1.0;
    a_lo[0] = 0.0;
    for (long j = 0; j < k; j++) {
        two_sum(row[j], -s->shift[j], &hi, &lo);
        a_hi[j + 1] = hi * s->inverse[j];
        a_lo[j + 1] = lo * s->inverse[j];
    }
    two_sum(s->y[i], -s->shift[k], &hi, &lo);
    *b_hi = hi * s->inverse[k];
    *b_lo = lo * s->inverse[k];
    if (!s->weights) return;
    double w = s->weights[i];
    double rw = sqrt(w); /* sqrt(w) to double-double by one Newton step */
    double rw_s_hi, rw_s_lo, rs_hi, rs_lo, h_hi, h_lo;
    split(rw, &rw_s_hi, &rw_s_lo);
    two_product(rw, rw_s_hi, rw_s_lo, rw, rw_s_hi, rw_s_lo, &p, &e);
    double rw_lo = ((w - p) - e) / (2.0 * rw);
    split(rw, &rs_hi, &rs_lo);
    for (long j = 0; j < k + 1; j++) {
        split(a_hi[j], &h_hi, &h_lo);
        two_product(a_hi[j], h_hi, h_lo, rw, rs_hi, rs_lo, &p, &e);
        e += a_hi[j] * rw_lo + a_lo[j] * rw;
        two_sum(p, e, &a_hi[j], &a_lo[j]);
    }
    split(*b_hi, &h_hi, &h_lo);
    two_product(*b_hi, h_hi, h_lo, rw, rs_hi, rs_lo, &p, &e);
    e += *b_hi * rw_lo + *b_lo * rw;
    two_sum(p, e, b_hi, b_lo);
}

/* One pass over the rows: r = b - A x (first) or f = b - r - A x, then g = -A' r.
 * `work` has room for 6 (k + 1) values. */
static void residual_pass(const Pass *s, double *work)
{
    const long k1 = s->k + 1;
    double *xs_hi = work, *xs_lo = work + k1, *a_hi = work + 2 * k1, *a_lo = work + 3 * k1;
    double *acc_hi = work + 4 * k1, *acc_err = work + 5 * k1;
    for (long j = 0; j < k1; j++) {
        split(s->x_hi[j], &xs_hi[j], &xs_lo[j]);
        acc_hi[j] = 0.0;
        acc_err[j] = 0.0;
    }
    for (long i = 0; i < s->n; i++) {
        double b_hi, b_lo, sum, err, p, e, e2, h_hi, h_lo;
        design_row(s, i, a_hi, a_lo, &b_hi, &b_lo);
        /* s = b - r - A x, by Dot2: the float64 sum in sum, every rounding error in err */
        sum = b_hi;
        err = b_lo;
        if (!s->first) {
            two_sum(sum, -s->r_hi[i], &sum, &e);
            err += e - s->r_lo[i];
        }
        for (long j = 0; j < k1; j++) {
            split(a_hi[j], &h_hi, &h_lo);
            two_product(a_hi[j], h_hi, h_lo, s->x_hi[j], xs_hi[j], xs_lo[j], &p, &e);
            two_sum(sum, -p, &sum, &e2);
            err += e2 - e - (a_hi[j] * s->x_lo[j] + a_lo[j] * s->x_hi[j]);
        }
        two_sum(sum, err, &sum, &err);
        if (s->first) {
            s->r_hi[i] = sum;
            s->r_lo[i] = err;
        } else {
            s->f[i] = sum;
        }
        /* g -= a r, with the row's residual after the pass */
        double rh = s->r_hi[i], rl = s->r_lo[i], rh_hi, rh_lo;
        split(rh, &rh_hi, &rh_lo);
        for (long j = 0; j < k1; j++) {
            split(a_hi[j], &h_hi, &h_lo);
            two_product(a_hi[j], h_hi, h_lo, rh, rh_hi, rh_lo, &p, &e);
            two_sum(acc_hi[j], -p, &acc_hi[j], &e2);
            acc_err[j] += e2 - e - (a_hi[j] * rl + a_lo[j] * rh);
        }
    }
    for (long j = 0; j < k1; j++) two_sum(acc_hi[j], acc_err[j], &s->g_hi[j], &s->g_lo[j]);
}

/* The arrays of residual_pass after X: y, shift, inverse, weights, x_hi, x_lo, r_hi, r_lo,
 * f, g_hi, g_lo. */
enum { Y, SHIFT, INVERSE, WEIGHTS, X_HI, X_LO, R_HI, R_LO, F, G_HI, G_LO, VECTORS };

static const char *const NAMES[VECTORS] = {
    "y", "shift", "inverse", "weights", "x_hi", "x_lo", "r_hi", "r_lo", "f", "g_hi", "g_lo"};

/* X (C-contiguous 2-D float64) into `matrix`, the vectors into `views`, their lengths
 * checked against n rows and k columns; 0, or -1 with the exception set and all released. */
static int take_pass(PyObject *X, PyObject **objects, Py_buffer *matrix, Py_buffer *views,
                     int first)
{
    if (PyObject_GetBuffer(X, matrix, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) != 0 ||
        matrix->ndim != 2 || !hrgtc_kind(matrix, HRGTC_F64, 8)) {
        if (PyErr_Occurred()) PyErr_Clear();
        else PyBuffer_Release(matrix);
        PyErr_SetString(PyExc_TypeError, "X must be a C-contiguous 2-D float64 numpy array");
        return -1;
    }
    long n = (long)matrix->shape[0], k = (long)matrix->shape[1];
    for (int i = 0; i < VECTORS; i++) {
        if (hrgtc_vector(objects[i], &views[i], HRGTC_F64, 8, i >= R_HI, NAMES[i])) {
            hrgtc_release(views, i);
            PyBuffer_Release(matrix);
            return -1;
        }
    }
    for (int i = 0; i < VECTORS; i++) {
        Py_ssize_t want = i == SHIFT || i == INVERSE || i == X_HI || i == X_LO ||
                                  i == G_HI || i == G_LO ? k + 1 : n;
        Py_ssize_t got = hrgtc_len(&views[i]);
        int optional = i == WEIGHTS || (i == F && first);
        if (got != want && !(optional && got == 0)) {
            PyErr_Format(PyExc_ValueError, "%s has %zd items; X of %ld rows and %ld columns "
                         "needs %zd%s", NAMES[i], got, n, k, want,
                         optional ? " (or none)" : "");
            hrgtc_release(views, VECTORS);
            PyBuffer_Release(matrix);
            return -1;
        }
    }
    return 0;
}

static PyObject *py_residual_pass(PyObject *self, PyObject *args)
{
    PyObject *X, *objects[VECTORS];
    int first;
    (void)self;
    if (!PyArg_ParseTuple(args, "OO(OO)O(OO)(OO)O(OO)p", &X, &objects[Y], &objects[SHIFT],
                          &objects[INVERSE], &objects[WEIGHTS], &objects[X_HI],
                          &objects[X_LO], &objects[R_HI], &objects[R_LO], &objects[F],
                          &objects[G_HI], &objects[G_LO], &first))
        return NULL;
    Py_buffer matrix, views[VECTORS];
    if (take_pass(X, objects, &matrix, views, first)) return NULL;
    Pass pass = {
        .X = matrix.buf, .y = views[Y].buf, .shift = views[SHIFT].buf,
        .inverse = views[INVERSE].buf,
        .weights = hrgtc_len(&views[WEIGHTS]) ? views[WEIGHTS].buf : NULL,
        .x_hi = views[X_HI].buf, .x_lo = views[X_LO].buf, .r_hi = views[R_HI].buf,
        .r_lo = views[R_LO].buf, .f = views[F].buf, .g_hi = views[G_HI].buf,
        .g_lo = views[G_LO].buf, .n = (long)matrix.shape[0], .k = (long)matrix.shape[1],
        .first = first,
    };
    double *work = malloc(sizeof(double) * 6 * (size_t)(pass.k + 1));
    if (work) {
        Py_BEGIN_ALLOW_THREADS
        residual_pass(&pass, work);
        Py_END_ALLOW_THREADS
        free(work);
    }
    hrgtc_release(views, VECTORS);
    PyBuffer_Release(&matrix);
    if (!work) return PyErr_NoMemory();
    Py_RETURN_NONE;
}

static PyObject *py_add_to(PyObject *self, PyObject *args)
{
    PyObject *objects[3];
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO", &objects[0], &objects[1], &objects[2])) return NULL;
    static const char *const names[3] = {"hi (float64)", "lo (float64)",
                                         "increment (float64)"};
    Py_buffer views[3];
    for (int i = 0; i < 3; i++) {
        if (hrgtc_vector(objects[i], &views[i], HRGTC_F64, 8, i < 2, names[i])) {
            hrgtc_release(views, i);
            return NULL;
        }
    }
    Py_ssize_t n = hrgtc_len(&views[0]);
    if (hrgtc_len(&views[1]) != n || hrgtc_len(&views[2]) != n) {
        PyErr_Format(PyExc_ValueError, "hi, lo and increment must have one length, got %zd, "
                     "%zd and %zd", n, hrgtc_len(&views[1]), hrgtc_len(&views[2]));
        hrgtc_release(views, 3);
        return NULL;
    }
    double *hi = views[0].buf, *lo = views[1].buf;
    const double *increment = views[2].buf;
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t i = 0; i < n; i++) { /* (hi, lo) += increment, in double-double */
        double s, e;
        two_sum(hi[i], increment[i], &s, &e);
        two_sum(s, e + lo[i], &hi[i], &lo[i]);
    }
    Py_END_ALLOW_THREADS
    hrgtc_release(views, 3);
    Py_RETURN_NONE;
}

static PyMethodDef methods[] = {
    {"residual_pass", py_residual_pass, METH_VARARGS,
     "residual_pass(X, y, (shift, inverse), weights, (x_hi, x_lo), (r_hi, r_lo), f,\n"
     "              (g_hi, g_lo), first) -> None\n\n"
     "One pass over the rows in double-double (see hrgtc.drift._extended_kernel)."},
    {"add_to", py_add_to, METH_VARARGS,
     "add_to(hi, lo, increment) -> None: (hi, lo) += increment in double-double."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_extended_native",
    "The refinement's double-double pass (see _extended_native.c).", -1, methods,
    NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__extended_native(void) { return PyModule_Create(&module); }
