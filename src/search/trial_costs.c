/* trial_costs.c - the costs of a hill-climbing trial, several points at once.
 * Takes: the points a prepared move lists (copied by field) and one trial
 * segment. Gives: each point's cost on that segment, folded into a running
 * minimum. The loop has no branches, so that the compiler can vectorise it;
 * it is built with -fno-trapping-math (Makefile), without which gcc keeps
 * the comparisons as branches. The same flag on trial.c made its branchy
 * per-point code slower, hence a file of its own. */
#include "../opt_state.h"

/* Each value is the one trial.h's polyc__seg_pre_cost computes, operation for
 * operation, selected instead of branched to. */
void polyc__trial_costs_min(const polyc__opt *o, const polyc__seg_pre *q, float *restrict c)
{
    const float *restrict X = o->ev.lsoa_x, *restrict Y = o->ev.lsoa_y, *restrict W = o->ev.lsoa_w;
    const float *restrict XX = o->ev.lsoa_cxx, *restrict XY = o->ev.lsoa_cxy, *restrict YY = o->ev.lsoa_cyy;
    const float ax = q->ax, ay = q->ay, bx = q->bx, by = q->by, dx = q->dx, dy = q->dy;
    const float il2 = q->inv_l2, nx = q->nx, ny = q->ny;
    const float nxx = nx * nx, nxy2 = 2.0f * nx * ny, nyy = ny * ny;
    const int point_like = il2 == 0.0f;
    const int32_t n = o->ev.lsoa_n;
    for (int32_t k = 0; k < n; k++) {
        float px = X[k], py = Y[k], w = W[k], cxx = XX[k], cyy = YY[k];
        float mx = px - ax, my = py - ay;
        float t = (mx * dx + my * dy) * il2;
        float ca = w * (mx * mx + my * my) + (cxx + cyy);
        float ex = px - bx, ey = py - by;
        float cb = w * (ex * ex + ey * ey) + (cxx + cyy);
        float d = nx * mx + ny * my;
        float ci = w * d * d + (nxx * cxx + nxy2 * XY[k] + nyy * cyy);
        ci = ci > 0.0f ? ci : 0.0f;
        float cj = t >= 1.0f ? cb : ci;
        cj = (t <= 0.0f) | point_like ? ca : cj;
        c[k] = cj < c[k] ? cj : c[k];
    }
}
