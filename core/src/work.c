/* The work space of one integration (work.h): one allocation for all of the methods' vectors. */
#include "work.h"

#include <stdlib.h>
#include <string.h>

tf_status tf_work_setup(work *w, const tf_ode *ode, const tf_solver_options *opt, tf_solver_stats *st)
{
    int n = ode->n;
    memset(w, 0, sizeof *w);
    w->t_clamp = INFINITY;
    w->ode = ode; w->opt = opt; w->st = st; w->n = n;
    size_t nvec = 7 + 4 + 5 + 3;
    w->block = (double *)malloc(sizeof(double) * (nvec * n + 3 * (size_t)n * n) + sizeof(int) * 5 * n);
    if (!w->block) return TF_ERR_NO_MEMORY;
    double *p = w->block;
    for (int i = 0; i < 7; i++, p += n) w->k[i] = p;
    w->ytmp = p; p += n;
    w->y1 = p; p += n;
    w->ysti = p; p += n;
    w->ft = p; p += n;
    for (int i = 0; i < 5; i++, p += n) w->cont[i] = p;
    w->J = p; p += n * n;
    w->W = p; p += n * n;
    w->Jpos = p; p += n * n;
    w->dinv = p; p += n;
    w->xr = p; p += n;
    w->rtol_w = p; p += n;
    for (int i = 0; i < n; i++) w->rtol_w[i] = opt->rtol_weight ? opt->rtol_weight[i] : 1.0;
    w->piv = (int *)p;
    w->pos = w->piv + n;
    w->partner = w->pos + n;
    w->red = w->partner + n;
    w->qcol = w->red + n;
    return TF_OK;
}

void tf_work_free(work *w)
{
    free(w->block);
    w->block = 0;
}
