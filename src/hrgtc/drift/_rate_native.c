/* The df/dt filter's step (hrgtc.drift.rate_filter), over whole arrays.
 *
 * Private to hrgtc.drift._rate_kernel (its Python side); built by `pip install -e .`
 * (setup.py). Why C and not numba: `calibrate` and `compensate` paid numba's import, its
 * first-call start and the loading of two cached kernels for passes of milliseconds
 * (docs/architecture.md, "The native kernels").
 *
 * The statements are those of the numba filter_run (hrgtc.drift._rate_numba, which the
 * fused compensation kernel still calls), in the same order, so the two compute the same
 * bits (tests/drift/test_rate_native.py compares them): one operation per statement,
 * -ffp-contract=off (setup.py) so no product is fused into an add, expm1 from the C
 * library as numba's math.expm1. The series coefficients, their limit and the step's
 * relative tolerance come from hrgtc.drift.rate_weights through the Python side.
 */
#include "../_buffers.h"
#include <math.h>
#include <stdint.h>

#define TERMS 9

/* The value of v as it is, from here on: without this, gcc rewrites r - (-e) as r + e and
 * may then add e first, which gives a NaN r the sign of e's NaN (numba keeps r's). */
#if defined(__GNUC__) && defined(__x86_64__)
#define OPAQUE(v) __asm__("" : "+x"(v)) /* in its SSE register: no store and load */
#elif defined(__GNUC__)
#define OPAQUE(v) __asm__ volatile("" : "+m"(v))
#else
#define OPAQUE(v) ((void)0)
#endif

typedef struct {
    double s[TERMS]; /* s[k - 1]: the coefficient of r^k of p's Taylor series */
    double limit;    /* below this r the series is used */
    double tolerance; /* a step within this of the cached one keeps its (a, p) */
} Series;

/* The state slots of hrgtc.drift.rate_filter.LAG ... */
enum { LAG, DIFFERENCE, PREVIOUS, T_PREV, STARTED, DT_C, A, P, SLOTS };

/* (a, p) of one step dt_s: a = 1 - exp(-r), p = 1 - a/r, r = dt/tau. */
static inline void step_weights(double dt_s, double tau_s, const Series *series, double *a_out,
                                double *p_out)
{
    const double *s = series->s;
    double r = dt_s / tau_s;
    double a = -expm1(-r);
    double p;
    OPAQUE(a);
    if (r < series->limit) { /* Taylor series of p, Horner, highest power first */
        p = s[8];
        p = p * r + s[7];
        p = p * r + s[6];
        p = p * r + s[5];
        p = p * r + s[4];
        p = p * r + s[3];
        p = p * r + s[2];
        p = p * r + s[1];
        p = p * r + s[0];
        p = p * r;
    } else {
        p = (r - a) / r;
    }
    *a_out = a;
    *p_out = p;
}

/* Advance `state` over x[:n] at time_s, writing each rate (and, unless lag_out is NULL,
 * the lag x - y1 after the step). restart (or NULL: none) or a state never started puts
 * the filter at rest on that sample (rate 0) with no cached step. A step of zero or
 * negative dt moves nothing but the previous input. */
static inline __attribute__((always_inline)) void run(
    const double *x, const double *time_s, long n, double tau_s, const int8_t *restart,
    double *state, double *rate_out, double *lag_out, const Series *series)
{
    double lag = state[LAG], difference = state[DIFFERENCE], previous = state[PREVIOUS];
    double t_prev = state[T_PREV], started = state[STARTED], dt_c = state[DT_C];
    double a = state[A], p = state[P];
    const double tolerance = series->tolerance;
    for (long i = 0; i < n; i++) {
        double xi = x[i], ti = time_s[i];
        if ((restart && restart[i] != 0) || started == 0.0) {
            lag = 0.0;
            difference = 0.0;
            previous = xi;
            t_prev = ti;
            started = 1.0;
            dt_c = -1.0; /* no cached step: a restarted filter is a new one */
            a = 0.0;
            p = 0.0;
            rate_out[i] = 0.0;
        } else {
            double dt = ti - t_prev;
            dt = !(dt > 0.0) ? 0.0 : dt;
            if (!(fabs(dt - dt_c) <= tolerance * dt_c)) {
                step_weights(dt, tau_s, series, &a, &p);
                dt_c = dt;
            }
            double delta = xi - previous;
            double c1 = a * lag;
            c1 = c1 + p * delta;
            lag = lag + delta;
            lag = lag - c1;
            double c2 = a * difference;
            c2 = c2 + p * c1;
            difference = difference + c1;
            difference = difference - c2;
            previous = xi;
            t_prev = ti;
            rate_out[i] = difference / tau_s;
        }
        if (lag_out) lag_out[i] = lag;
    }
    state[LAG] = lag;
    state[DIFFERENCE] = difference;
    state[PREVIOUS] = previous;
    state[T_PREV] = t_prev;
    state[STARTED] = started;
    state[DT_C] = dt_c;
    state[A] = a;
    state[P] = p;
}

/* run() compiled once per case of restart and lag_out present or NULL: the tests of the
 * loop are then constants (a few per cent of the pass). */
static void filter_run(const double *x, const double *time_s, long n, double tau_s,
                       const int8_t *restart, double *state, double *rate_out,
                       double *lag_out, const Series *series)
{
    if (restart && lag_out)
        run(x, time_s, n, tau_s, restart, state, rate_out, lag_out, series);
    else if (restart)
        run(x, time_s, n, tau_s, restart, state, rate_out, NULL, series);
    else if (lag_out)
        run(x, time_s, n, tau_s, NULL, state, rate_out, lag_out, series);
    else
        run(x, time_s, n, tau_s, NULL, state, rate_out, NULL, series);
}

#define SERIES_FORMAT "(ddddddddddd)"
#define SERIES_FIELDS(series)                                                            \
    &(series).s[0], &(series).s[1], &(series).s[2], &(series).s[3], &(series).s[4],     \
        &(series).s[5], &(series).s[6], &(series).s[7], &(series).s[8], &(series).limit, \
        &(series).tolerance

static PyObject *py_step_weights(PyObject *self, PyObject *args)
{
    double dt_s, tau_s, a, p;
    Series series;
    (void)self;
    if (!PyArg_ParseTuple(args, "dd" SERIES_FORMAT, &dt_s, &tau_s, SERIES_FIELDS(series)))
        return NULL;
    step_weights(dt_s, tau_s, &series, &a, &p);
    return Py_BuildValue("(dd)", a, p);
}

/* The arrays of rate_pass: x, time_s, restart, state, out_rate, out_lag. */
enum { X, TIME, RESTART, STATE, RATE, LAG_OUT, ARRAYS };

static int take_arrays(PyObject **objects, Py_buffer *views)
{
    static const char *const kinds[ARRAYS] = {HRGTC_F64, HRGTC_F64, "b?B", HRGTC_F64,
                                              HRGTC_F64, HRGTC_F64};
    static const Py_ssize_t sizes[ARRAYS] = {8, 8, 1, 8, 8, 8};
    static const char *const names[ARRAYS] = {
        "x (float64)", "time_s (float64)", "restart (int8)", "state (float64)",
        "out_rate (float64)", "out_lag (float64)"};
    for (int i = 0; i < ARRAYS; i++) {
        int writable = i >= STATE;
        if (hrgtc_vector(objects[i], &views[i], kinds[i], sizes[i], writable, names[i])) {
            hrgtc_release(views, i);
            return -1;
        }
    }
    Py_ssize_t n = hrgtc_len(&views[X]), restart = hrgtc_len(&views[RESTART]);
    Py_ssize_t lag = hrgtc_len(&views[LAG_OUT]);
    if (hrgtc_len(&views[TIME]) != n || hrgtc_len(&views[RATE]) != n ||
        (restart != 0 && restart != n) || (lag != 0 && lag != n) ||
        hrgtc_len(&views[STATE]) < SLOTS) {
        PyErr_Format(PyExc_ValueError,
                     "rate_pass needs x, time_s and out_rate of one length (got %zd, %zd, "
                     "%zd), restart and out_lag of it or empty (%zd, %zd), and %d state "
                     "slots or more (%zd)", n, hrgtc_len(&views[TIME]), hrgtc_len(&views[RATE]),
                     restart, lag, SLOTS, hrgtc_len(&views[STATE]));
        hrgtc_release(views, ARRAYS);
        return -1;
    }
    return 0;
}

static PyObject *py_rate_pass(PyObject *self, PyObject *args)
{
    PyObject *objects[ARRAYS];
    double tau_s;
    Series series;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOdOOOO" SERIES_FORMAT, &objects[X], &objects[TIME], &tau_s,
                          &objects[RESTART], &objects[STATE], &objects[RATE],
                          &objects[LAG_OUT], SERIES_FIELDS(series)))
        return NULL;
    Py_buffer views[ARRAYS];
    if (take_arrays(objects, views)) return NULL;
    long n = (long)hrgtc_len(&views[X]);
    const int8_t *restart = hrgtc_len(&views[RESTART]) ? views[RESTART].buf : NULL;
    double *lag = hrgtc_len(&views[LAG_OUT]) ? views[LAG_OUT].buf : NULL;
    Py_BEGIN_ALLOW_THREADS
    filter_run(views[X].buf, views[TIME].buf, n, tau_s, restart, views[STATE].buf,
               views[RATE].buf, lag, &series);
    Py_END_ALLOW_THREADS
    hrgtc_release(views, ARRAYS);
    Py_RETURN_NONE;
}

/* (kind, row) of the first time the filter cannot step to: kind 1 not finite, 2 a step
 * back, 3 a step back from the previous chunk (t_prev); (0, -1) if none. */
static void first_time_problem(const double *t, long n, double t_prev, double started,
                               long *kind, long *row)
{
    *kind = 0;
    *row = -1;
    for (long i = 0; i < n; i++) {
        if (!isfinite(t[i])) {
            *kind = 1;
            *row = i;
            return;
        }
        if (i == 0) {
            if (started != 0.0 && t[0] < t_prev) {
                *kind = 3;
                *row = 0;
                return;
            }
        } else if (t[i] < t[i - 1]) {
            *kind = 2;
            *row = i;
            return;
        }
    }
}

static PyObject *py_first_time_problem(PyObject *self, PyObject *args)
{
    PyObject *object;
    double t_prev, started;
    long kind, row;
    (void)self;
    if (!PyArg_ParseTuple(args, "Odd", &object, &t_prev, &started)) return NULL;
    Py_buffer view;
    if (hrgtc_vector(object, &view, HRGTC_F64, 8, 0, "time_s (float64)")) return NULL;
    Py_BEGIN_ALLOW_THREADS
    first_time_problem(view.buf, (long)hrgtc_len(&view), t_prev, started, &kind, &row);
    Py_END_ALLOW_THREADS
    PyBuffer_Release(&view);
    return Py_BuildValue("(ll)", kind, row);
}

static PyMethodDef methods[] = {
    {"step_weights", py_step_weights, METH_VARARGS,
     "step_weights(dt_s, tau_s, series) -> (a, p)\n\n"
     "series: the 9 Taylor coefficients of p, the series' limit and the step tolerance."},
    {"rate_pass", py_rate_pass, METH_VARARGS,
     "rate_pass(x, time_s, tau_s, restart, state, out_rate, out_lag, series) -> None\n\n"
     "The df/dt filter over whole arrays (contiguous 1-D: float64, restart int8 or empty,\n"
     "out_lag empty or of x's length, state the 8 slots of rate_filter.LAG), in place."},
    {"first_time_problem", py_first_time_problem, METH_VARARGS,
     "first_time_problem(time_s, t_prev, started) -> (kind, row)"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_rate_native", "The df/dt filter's step (see _rate_native.c).",
    -1, methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__rate_native(void) { return PyModule_Create(&module); }
