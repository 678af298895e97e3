/* A* (and Dijkstra) of planners/grid_search.py astar_cells, compiled: the same expansions, parents and cost.
 *
 * astar(masks, offsets, costs, cols, diagonal_extra, weight, start, goal)
 *     -> (cells from start to goal as flat indices, or None when the goal is unreachable; cost; expansions)
 *
 * masks: uint8 per cell, bit k set where move k is legal (planners/grid_graph.py move_masks);
 * offsets: 8 int64 flat-index offsets of the moves; costs: their 8 float64 costs; the heuristic is
 * weight x the octile distance (diagonal_extra = sqrt(2) - 1), none (Dijkstra) with weight 0.  The open list is ordered by (f, -g, cell), the key of the
 * Python search's heapq tuples; every key is distinct (a cell is pushed again only with a smaller
 * g), so any correct priority queue pops the same sequence, and g, f = g + h and the strict
 * improvement test are the same double operations: the search is the Python one's, step for step.
 * Built with -ffp-contract=off (no fused multiply-add).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>
#include <math.h>
#include <stdlib.h>

typedef struct {
    double f, neg_g;
    int64_t v;
} Entry;

static int less(const Entry *a, const Entry *b) {
    if (a->f != b->f)
        return a->f < b->f;
    if (a->neg_g != b->neg_g)
        return a->neg_g < b->neg_g;
    return a->v < b->v;
}

typedef struct {
    Entry *items;
    Py_ssize_t size, capacity;
} Heap;

static int heap_push(Heap *h, Entry e) {
    if (h->size == h->capacity) {
        Py_ssize_t capacity = h->capacity ? 2 * h->capacity : 1024;
        Entry *items = realloc(h->items, (size_t)capacity * sizeof(Entry));
        if (!items)
            return 0;
        h->items = items;
        h->capacity = capacity;
    }
    Py_ssize_t i = h->size++;
    while (i > 0) {
        Py_ssize_t up = (i - 1) / 2;
        if (!less(&e, &h->items[up]))
            break;
        h->items[i] = h->items[up];
        i = up;
    }
    h->items[i] = e;
    return 1;
}

static Entry heap_pop(Heap *h) {
    Entry top = h->items[0], last = h->items[--h->size];
    Py_ssize_t i = 0;
    for (;;) {
        Py_ssize_t child = 2 * i + 1;
        if (child >= h->size)
            break;
        if (child + 1 < h->size && less(&h->items[child + 1], &h->items[child]))
            child++;
        if (!less(&h->items[child], &last))
            break;
        h->items[i] = h->items[child];
        i = child;
    }
    if (h->size)
        h->items[i] = last;
    return top;
}

/* The octile distance to the goal, as grid_search._octile_table computes it in NumPy (an int64
 * min times the double sqrt(2) - 1, plus the int64 max), times the weight unless it is 1. */
static double heuristic(int64_t v, Py_ssize_t cols, int64_t goal_row, int64_t goal_col, double diagonal_extra,
                        double weight) {
    int64_t dr = v / cols - goal_row, dc = v % cols - goal_col;
    if (dr < 0)
        dr = -dr;
    if (dc < 0)
        dc = -dc;
    const double h = diagonal_extra * (double)(dr < dc ? dr : dc) + (double)(dr > dc ? dr : dc);
    return weight == 1.0 ? h : weight * h;
}

static PyObject *astar(PyObject *self, PyObject *args) {
    Py_buffer b_masks, b_offsets, b_costs;
    Py_ssize_t cols, start, goal;
    double diagonal_extra, weight;
    if (!PyArg_ParseTuple(args, "y*y*y*nddnn", &b_masks, &b_offsets, &b_costs, &cols, &diagonal_extra, &weight,
                          &start, &goal))
        return NULL;
    PyObject *result = NULL, *parent_bytes = NULL;
    double *g = NULL;
    unsigned char *closed = NULL;
    Heap heap = {NULL, 0, 0};
    const Py_ssize_t n = b_masks.len;
    if (b_offsets.len != 8 * (Py_ssize_t)sizeof(int64_t) || b_costs.len != 8 * (Py_ssize_t)sizeof(double)
        || cols < 1 || n % cols || start < 0 || start >= n || goal < 0 || goal >= n) {
        PyErr_SetString(PyExc_ValueError, "astar: masks (one per cell of a cols-wide grid), 8 offsets and costs, "
                        "start and goal cells");
        goto done;
    }
    const unsigned char *masks = b_masks.buf;
    const int64_t *offsets = b_offsets.buf;
    const double *costs = b_costs.buf;
    const int64_t goal_row = goal / cols, goal_col = goal % cols;
    parent_bytes = PyBytes_FromStringAndSize(NULL, n * (Py_ssize_t)sizeof(int64_t));
    g = malloc((size_t)n * sizeof(double));
    closed = calloc((size_t)n, 1);
    if (!parent_bytes || !g || !closed) {
        PyErr_NoMemory();
        goto done;
    }
    int64_t *parent = (int64_t *)PyBytes_AS_STRING(parent_bytes);
    for (Py_ssize_t i = 0; i < n; i++) {
        g[i] = INFINITY;
        parent[i] = -1;
    }
    g[start] = 0.0;
    Py_ssize_t expansions = 0;
    int ok = 1;
    Py_BEGIN_ALLOW_THREADS
    Entry first = {weight != 0.0 ? heuristic(start, cols, goal_row, goal_col, diagonal_extra, weight) : 0.0, 0.0,
                   start};
    ok = heap_push(&heap, first);
    while (ok == 1 && heap.size) {
        Entry e = heap_pop(&heap);
        const int64_t u = e.v;
        if (closed[u])
            continue;
        closed[u] = 1;
        expansions++;
        if (u == goal)
            break;
        const double gu = g[u];
        const unsigned mask = masks[u];
        for (int k = 0; k < 8 && ok == 1; k++) {
            if (!(mask >> k & 1))
                continue;
            const int64_t v = u + offsets[k];
            if (v < 0 || v >= n) {   /* a mask that leaves the grid: refused below */
                ok = -1;
                break;
            }
            const double nv = gu + costs[k];
            if (nv < g[v]) {
                g[v] = nv;
                parent[v] = u;
                Entry next = {weight != 0.0 ? nv + heuristic(v, cols, goal_row, goal_col, diagonal_extra, weight)
                                            : nv, -nv, v};
                ok = heap_push(&heap, next);
            }
        }
    }
    Py_END_ALLOW_THREADS
    if (ok == 0) {
        PyErr_NoMemory();
        goto done;
    }
    if (ok < 0) {
        PyErr_SetString(PyExc_ValueError, "astar: a legal move leaves the grid (masks do not match the offsets)");
        goto done;
    }
    if (!closed[goal]) {
        result = Py_BuildValue("Odn", Py_None, g[goal], expansions);
        goto done;
    }
    Py_ssize_t count = 0;
    for (int64_t cur = goal; cur != -1; cur = parent[cur])
        count++;
    PyObject *path = PyList_New(count);
    if (!path)
        goto done;
    Py_ssize_t i = count;
    for (int64_t cur = goal; cur != -1; cur = parent[cur]) {
        PyObject *cell = PyLong_FromLongLong(cur);
        if (!cell) {
            Py_DECREF(path);
            goto done;
        }
        PyList_SET_ITEM(path, --i, cell);
    }
    result = Py_BuildValue("Ndn", path, g[goal], expansions);
done:
    Py_XDECREF(parent_bytes);
    free(g);
    free(closed);
    free(heap.items);
    PyBuffer_Release(&b_masks);
    PyBuffer_Release(&b_offsets);
    PyBuffer_Release(&b_costs);
    return result;
}

static PyMethodDef methods[] = {
    {"astar", astar, METH_VARARGS, "A* over legal-move masks; returns (path cells or None, cost, expansions)."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_grid_search",
                                   "A* of planners/grid_search.py, compiled.", -1, methods};

PyMODINIT_FUNC PyInit__grid_search(void) { return PyModule_Create(&module); }
