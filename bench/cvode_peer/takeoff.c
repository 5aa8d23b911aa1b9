/*
 * C + SUNDIALS CVODE peer of tcsim's isolated Hrovat & Tobler take-off (bench only, not packaged).
 *
 * Equations: Li & Sundén (2016), Chalmers MSc thesis 2016:74, eqs 2.12-2.15 with the losses of
 * eqs 2.19-2.25, transcribed from bench/scipy_reference.py (forward flow, sigma = +1):
 *
 *   M u' = F(u) + T(t, u),  u = [wp, wt, ws, Q] (rad/s, m^3/s),
 *
 * M the mass matrix (inertias, load inertia on the turbine, shape effects rho*S, rho*Lf/A), T the
 * pump torque table (piecewise linear, held at its ends) on the pump and -(T0 + cd*wt^2) on the
 * turbine. Modes: stator LOCKED (ws == 0 held, states [wp, wt, Q]) or FREE (states [wp, wt, ws, Q]);
 * each mode is the explicit ODE x' = M_xx^-1 (F + T)_x with M_xx^-1 computed once per mode.
 *
 * Solver: CVODE BDF (orders 1-5), Newton with the dense direct linear solver and the analytic
 * Jacobian M_xx^-1 dF/dx; rtol 1e-6, atol 1e-5 rad/s and 1e-8 m^3/s, first step 1e-5 s (tcsim's
 * defaults, crates/tcsim-core/src/engine/options.rs). Root finding as tcsim does it: LOCKED, the
 * holding torque T_s = rho*Ss*Q' - F_s (+1e-6 N m hysteresis), falling, releases the stator; FREE,
 * ws (+1e-4 rad/s), falling, locks it; Q (+1e-7 m^3/s), falling, is flow reversal, which this peer
 * does not model: it stops with exit status 1 (the take-off never reverses the flow). At an event
 * the run continues in the new mode from the state at the root (CVodeReInit). Initial state: wt = 0,
 * stator locked, wp and Q steady under the first pump torque (homogeneity: the steady state at
 * wp = 1 rad/s scaled by sqrt(Tp / Tp(1))), as tcsim's default.
 *
 * Input (stdin): "name value..." lines, names as in scipy_reference.load_parameters() plus IL, T0,
 * cd (load), table_t and table_T (pump torque table: count then values), t_end (s).
 * Usage: takeoff REPEATS SAMPLES < params.txt
 * Exit status: 0; 2 and one line "error: <where>: <name> = <value>: expected <what>" for bad arguments or
 * parameters; 1 and one "error: ..." line when CVODE fails or the flow reaches zero (not the input's fault).
 * Output (stdout): "timing median_s min_s repeats", "stats steps rhs jac lu roots", one "event t
 * kind" line per event, then one "sample t wp wt ws Q Tp Tt Ts Ploss" line per sample (last run).
 * Each run (timed with clock_gettime, CLOCK_MONOTONIC) does everything from the parameters to the
 * sample arrays: initial state, CVODE set-up of each mode it enters, integration, outputs, free.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#define MAXTAB 64
#define LOCKED 0
#define FREE 1

typedef struct {
  double Ip, It, Is, rho, A, Rp, Rt, Rs, tp, tt, ts, tpp, ttt, tss, Cp, Ct, Cs, f, Lf, Sp, St, Ss;
  double IL, T0, cd, t_end;
  int ntab;
  double tab_t[MAXTAB], tab_T[MAXTAB];
  /* derived */
  double M[4][4], a, b, c, kf, dV[3][4];
} Params;

typedef struct {
  const Params *p;
  int mode, n, free_[4];
  double Minv[4][4];
} Mode;

typedef struct {
  double *t, *wp, *wt, *ws, *Q, *Tp, *Tt, *Ts, *Ploss;
} Samples;

static double pump_torque(const Params *p, double t) {
  if (t <= p->tab_t[0]) return p->tab_T[0];
  for (int i = 1; i < p->ntab; i++)
    if (t <= p->tab_t[i])
      return p->tab_T[i - 1] + (p->tab_T[i] - p->tab_T[i - 1]) * (t - p->tab_t[i - 1]) / (p->tab_t[i] - p->tab_t[i - 1]);
  return p->tab_T[p->ntab - 1];
}

static void derive(Params *p) {
  double r = p->rho;
  double M[4][4] = {{p->Ip, 0, 0, r * p->Sp},
                    {0, p->It + p->IL, 0, r * p->St},
                    {0, 0, p->Is, r * p->Ss},
                    {r * p->Sp, r * p->St, r * p->Ss, r * p->Lf / p->A}};
  memcpy(p->M, M, sizeof M);
  p->a = p->Rp * p->tp - p->Rs * p->ts;
  p->b = p->Rt * p->tt - p->Rp * p->tp;
  p->c = p->Rs * p->ts - p->Rt * p->tt;
  p->kf = 0.5 * r * p->f * (3 + p->tp * p->tp + p->tt * p->tt + p->ts * p->ts);
  double dV[3][4] = {{-p->Rs, 0, p->Rs, (p->ts - p->tpp) / p->A},
                     {p->Rp, -p->Rp, 0, (p->tp - p->ttt) / p->A},
                     {0, p->Rt, -p->Rt, (p->tt - p->tss) / p->A}};
  memcpy(p->dV, dV, sizeof dV);
}

/* Right-hand sides of eqs 2.12-2.15 (sigma = +1), external torques included; P_loss out. */
static void forces(const Params *p, const double u[4], double t, double F[4], double *ploss) {
  double wp = u[0], wt = u[1], ws = u[2], Q = u[3], q = Q / p->A, r = p->rho;
  double Rp2 = p->Rp * p->Rp, Rt2 = p->Rt * p->Rt, Rs2 = p->Rs * p->Rs;
  double hp = wp * Rp2 + p->Rp * p->tp * q, ht = wt * Rt2 + p->Rt * p->tt * q, hs = ws * Rs2 + p->Rs * p->ts * q;
  double shock = 0, C[3] = {p->Cp, p->Ct, p->Cs};
  for (int i = 0; i < 3; i++) {
    double V = p->dV[i][0] * wp + p->dV[i][1] * wt + p->dV[i][2] * ws + p->dV[i][3] * Q;
    shock += C[i] * V * V;
  }
  double pl = 0.5 * r * shock + p->kf * q * q;
  double head = r * (Rp2 * wp * wp + Rt2 * wt * wt + Rs2 * ws * ws - Rs2 * wp * ws - Rp2 * wt * wp - Rt2 * ws * wt +
                     q * (wp * p->a + wt * p->b + ws * p->c));
  double rq = r * Q;
  F[0] = -rq * (hp - hs) + pump_torque(p, t);
  F[1] = -rq * (ht - hp) - (p->T0 + p->cd * wt * wt);
  F[2] = -rq * (hs - ht);
  F[3] = head - pl;
  *ploss = pl;
}

/* dF/du (4x4), analytic, the load's drag included. */
static void jacobian(const Params *p, const double u[4], double J[4][4]) {
  double wp = u[0], wt = u[1], ws = u[2], Q = u[3], r = p->rho, A = p->A, q = Q / A;
  double Rp2 = p->Rp * p->Rp, Rt2 = p->Rt * p->Rt, Rs2 = p->Rs * p->Rs;
  double hp = wp * Rp2 + p->Rp * p->tp * q, ht = wt * Rt2 + p->Rt * p->tt * q, hs = ws * Rs2 + p->Rs * p->ts * q;
  double rq = r * Q, C[3] = {p->Cp, p->Ct, p->Cs}, dP[4] = {0, 0, 0, 0};
  for (int i = 0; i < 3; i++) {
    double V = p->dV[i][0] * wp + p->dV[i][1] * wt + p->dV[i][2] * ws + p->dV[i][3] * Q;
    for (int k = 0; k < 4; k++) dP[k] += r * C[i] * V * p->dV[i][k];
  }
  dP[3] += 2 * p->kf * q / A;
  double Jl[4][4] = {
      {-rq * Rp2, 0.0, rq * Rs2, -r * (hp - hs) - rq * p->a / A},
      {rq * Rp2, -rq * Rt2 - 2 * p->cd * wt, 0.0, -r * (ht - hp) - rq * p->b / A},
      {0.0, rq * Rt2, -rq * Rs2, -r * (hs - ht) - rq * p->c / A},
      {r * (2 * Rp2 * wp - Rs2 * ws - Rp2 * wt + q * p->a) - dP[0], r * (2 * Rt2 * wt - Rp2 * wp - Rt2 * ws + q * p->b) - dP[1],
       r * (2 * Rs2 * ws - Rs2 * wp - Rt2 * wt + q * p->c) - dP[2], r * (wp * p->a + wt * p->b + ws * p->c) / A - dP[3]}};
  memcpy(J, Jl, sizeof Jl);
}

/* Inverse of the n x n leading block by Gauss-Jordan (M is symmetric positive definite). */
static void invert(int n, double a[4][4], double inv[4][4]) {
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) inv[i][j] = i == j;
  for (int k = 0; k < n; k++) {
    double d = a[k][k];
    for (int j = 0; j < n; j++) a[k][j] /= d, inv[k][j] /= d;
    for (int i = 0; i < n; i++)
      if (i != k) {
        double m = a[i][k];
        for (int j = 0; j < n; j++) a[i][j] -= m * a[k][j], inv[i][j] -= m * inv[k][j];
      }
  }
}

static void mode_init(Mode *m, const Params *p, int mode) {
  m->p = p, m->mode = mode, m->n = mode == LOCKED ? 3 : 4;
  int fl[3] = {0, 1, 3}, ff[4] = {0, 1, 2, 3};
  memcpy(m->free_, mode == LOCKED ? fl : ff, sizeof(int) * m->n);
  double a[4][4];
  for (int i = 0; i < m->n; i++)
    for (int j = 0; j < m->n; j++) a[i][j] = p->M[m->free_[i]][m->free_[j]];
  invert(m->n, a, m->Minv);
}

static void full(const Mode *m, const double *x, double u[4]) {
  u[0] = u[1] = u[2] = u[3] = 0;
  for (int i = 0; i < m->n; i++) u[m->free_[i]] = x[i];
}

/* u' in full coordinates (zero for the held stator), F and P_loss. */
static void rates(const Mode *m, const double u[4], double t, double ud[4], double F[4], double *ploss) {
  forces(m->p, u, t, F, ploss);
  ud[0] = ud[1] = ud[2] = ud[3] = 0;
  for (int i = 0; i < m->n; i++) {
    double s = 0;
    for (int j = 0; j < m->n; j++) s += m->Minv[i][j] * F[m->free_[j]];
    ud[m->free_[i]] = s;
  }
}

static int rhs(double t, N_Vector y, N_Vector yd, void *data) {
  const Mode *m = data;
  double u[4], ud[4], F[4], pl, *xd = N_VGetArrayPointer(yd);
  full(m, N_VGetArrayPointer(y), u);
  rates(m, u, t, ud, F, &pl);
  for (int i = 0; i < m->n; i++) xd[i] = ud[m->free_[i]];
  return 0;
}

static int jac(double t, N_Vector y, N_Vector fy, SUNMatrix Jm, void *data, N_Vector t1, N_Vector t2, N_Vector t3) {
  (void)t, (void)fy, (void)t1, (void)t2, (void)t3;
  const Mode *m = data;
  double u[4], J[4][4];
  full(m, N_VGetArrayPointer(y), u);
  jacobian(m->p, u, J);
  for (int i = 0; i < m->n; i++)
    for (int j = 0; j < m->n; j++) {
      double s = 0;
      for (int k = 0; k < m->n; k++) s += m->Minv[i][k] * J[m->free_[k]][m->free_[j]];
      SM_ELEMENT_D(Jm, i, j) = s;
    }
  return 0;
}

/* Event functions, positive while the mode holds (tcsim's hysteresis added). */
static int roots(double t, N_Vector y, double *g, void *data) {
  const Mode *m = data;
  double u[4], ud[4], F[4], pl;
  full(m, N_VGetArrayPointer(y), u);
  if (m->mode == LOCKED) {
    rates(m, u, t, ud, F, &pl);
    g[0] = m->p->rho * m->p->Ss * ud[3] - F[2] + 1e-6; /* holding torque T_s, N m */
  } else {
    g[0] = u[2] + 1e-4; /* stator speed, rad/s */
  }
  g[1] = u[3] + 1e-7; /* flow, m^3/s */
  return 0;
}

static void sample(const Mode *m, const double u[4], double t, Samples *s, int k) {
  const Params *p = m->p;
  double ud[4], F[4], pl;
  rates(m, u, t, ud, F, &pl);
  s->t[k] = t, s->wp[k] = u[0], s->wt[k] = u[1], s->ws[k] = u[2], s->Q[k] = u[3];
  s->Tp[k] = pump_torque(p, t);
  s->Tt[k] = F[1] + p->T0 + p->cd * u[1] * u[1] - p->It * ud[1] - p->rho * p->St * ud[3];
  s->Ts[k] = m->mode == LOCKED ? p->rho * p->Ss * ud[3] - F[2] : 0.0;
  s->Ploss[k] = u[3] * pl;
}

typedef struct {
  long steps, rhs, jac, lu, groots;
  int nevents;
  double ev_t[16];
  int ev_kind[16]; /* 0 stator release, 1 stator lock */
} Stats;

typedef struct {
  void *mem;
  N_Vector y;
  SUNMatrix J;
  SUNLinearSolver LS;
} Cv;

static int cv_start(Cv *cv, SUNContext ctx, Mode *m, double t0, const double u[4], double t_end) {
  cv->y = N_VNew_Serial(m->n, ctx);
  double *x = N_VGetArrayPointer(cv->y);
  for (int i = 0; i < m->n; i++) x[i] = u[m->free_[i]];
  N_Vector atol = N_VNew_Serial(m->n, ctx);
  for (int i = 0; i < m->n; i++) NV_Ith_S(atol, i) = m->free_[i] == 3 ? 1e-8 : 1e-5;
  cv->mem = CVodeCreate(CV_BDF, ctx);
  int dirs[2] = {-1, -1};
  int bad = CVodeInit(cv->mem, rhs, t0, cv->y) || CVodeSVtolerances(cv->mem, 1e-6, atol) ||
            CVodeSetUserData(cv->mem, m) || CVodeSetInitStep(cv->mem, 1e-5) ||
            CVodeSetMaxNumSteps(cv->mem, 100000) || CVodeSetStopTime(cv->mem, t_end);
  N_VDestroy(atol);
  cv->J = SUNDenseMatrix(m->n, m->n, ctx);
  cv->LS = SUNLinSol_Dense(cv->y, cv->J, ctx);
  bad = bad || CVodeSetLinearSolver(cv->mem, cv->LS, cv->J) || CVodeSetJacFn(cv->mem, jac) ||
        CVodeRootInit(cv->mem, 2, roots) || CVodeSetRootDirection(cv->mem, dirs);
  return bad;
}

static void cv_stop(Cv *cv, Stats *st) {
  long a = 0;
  CVodeGetNumSteps(cv->mem, &a), st->steps += a;
  CVodeGetNumRhsEvals(cv->mem, &a), st->rhs += a;
  CVodeGetNumJacEvals(cv->mem, &a), st->jac += a;
  CVodeGetNumLinSolvSetups(cv->mem, &a), st->lu += a;
  CVodeGetNumGEvals(cv->mem, &a), st->groots += a;
  CVodeFree(&cv->mem);
  SUNLinSolFree(cv->LS);
  SUNMatDestroy(cv->J);
  N_VDestroy(cv->y);
}

/* wt = 0, stator locked: the steady state at wp = 1 rad/s (F_Q(Q) = 0 is a quadratic in Q), scaled. */
static int initial_state(const Params *p, double u[4]) {
  double fq[3], F[4], pl;
  for (int k = 0; k < 3; k++) {
    double v[4] = {1.0, 0.0, 0.0, (k - 1) * p->A};
    Params q = *p;
    q.ntab = 1, q.tab_T[0] = 0.0, q.T0 = 0.0;
    forces(&q, v, 0.0, F, &pl);
    fq[k] = F[3];
  }
  double a = 0.5 * (fq[2] + fq[0]) - fq[1], b = 0.5 * (fq[2] - fq[0]), c = fq[1];
  double disc = b * b - 4 * a * c;
  if (disc < 0) return 1;
  double r1 = (-b + sqrt(disc)) / (2 * a), r2 = (-b - sqrt(disc)) / (2 * a), s = fmax(r1, r2);
  if (!(s > 0)) return 1;
  double Q1 = s * p->A;
  double Rs = p->Rs, hp = p->Rp * p->Rp + p->Rp * p->tp * s, hs = Rs * p->ts * s;
  double tp1 = p->rho * (hp - hs) * Q1, tp0 = pump_torque(p, 0.0);
  if (!(tp1 > 0 && tp0 > 0)) return 1;
  double k = sqrt(tp0 / tp1);
  u[0] = k, u[1] = 0.0, u[2] = 0.0, u[3] = Q1 * k;
  return 0;
}

static double last_t; /* time reached by the last run, s (for the failure message) */

/* One take-off: 0 on success, 2 on a solver failure, 3 on flow reversal (not modelled), 4 without a
 * steady initial state. */
static int run(const Params *p, SUNContext ctx, const double *times, int ns, Samples *s, Stats *st) {
  Mode modes[2];
  mode_init(&modes[LOCKED], p, LOCKED);
  mode_init(&modes[FREE], p, FREE);
  memset(st, 0, sizeof *st);
  double u[4];
  if (initial_state(p, u)) return 4;
  int mode = LOCKED, k = 0;
  Cv cv;
  if (cv_start(&cv, ctx, &modes[mode], 0.0, u, p->t_end)) return 2;
  double t = 0.0;
  while (k < ns && times[k] <= t) sample(&modes[mode], u, times[k], s, k), k++;
  while (k < ns) {
    int flag = CVode(cv.mem, times[k], cv.y, &t, CV_NORMAL);
    last_t = t;
    if (flag < 0) return cv_stop(&cv, st), 2;
    full(&modes[mode], N_VGetArrayPointer(cv.y), u);
    if (flag == CV_ROOT_RETURN) {
      int found[2] = {0, 0};
      CVodeGetRootInfo(cv.mem, found);
      if (found[1]) return cv_stop(&cv, st), 3;
      /* CVode stops at the first of tout = times[k] and the root: the samples before the root are done */
      if (st->nevents < 16) st->ev_t[st->nevents] = t, st->ev_kind[st->nevents] = mode == LOCKED ? 0 : 1;
      st->nevents++;
      cv_stop(&cv, st);
      if (mode == FREE) u[2] = 0.0;
      mode = 1 - mode;
      if (cv_start(&cv, ctx, &modes[mode], t, u, p->t_end)) return 2;
      continue;
    }
    sample(&modes[mode], u, times[k], s, k), k++;
  }
  cv_stop(&cv, st);
  return 0;
}

/* A number from the token `text` of parameter `name`; else one error line (project format) and 0. */
static int number(const char *name, const char *text, double *out) {
  char *end;
  *out = strtod(text, &end);
  if (end != text && *end == '\0' && isfinite(*out)) return 1;
  fprintf(stderr, "error: stdin: %s = %s: expected a finite number\n", name, text);
  return 0;
}

/* Parameters from stdin; 0 on success, else one error line on stderr and 1. */
static int read_params(Params *p) {
  char name[64], text[64];
  memset(p, 0, sizeof *p);
  p->t_end = 10.0;
  struct { const char *n; double *v; } keys[] = {
      {"Ip", &p->Ip}, {"It", &p->It}, {"Is", &p->Is}, {"rho", &p->rho}, {"A", &p->A}, {"Rp", &p->Rp},
      {"Rt", &p->Rt}, {"Rs", &p->Rs}, {"tp", &p->tp}, {"tt", &p->tt}, {"ts", &p->ts}, {"tpp", &p->tpp},
      {"ttt", &p->ttt}, {"tss", &p->tss}, {"Cp", &p->Cp}, {"Ct", &p->Ct}, {"Cs", &p->Cs}, {"f", &p->f},
      {"Lf", &p->Lf}, {"Sp", &p->Sp}, {"St", &p->St}, {"Ss", &p->Ss}, {"IL", &p->IL}, {"T0", &p->T0},
      {"cd", &p->cd}, {"t_end", &p->t_end}};
  int nkeys = sizeof keys / sizeof keys[0], ntab[2] = {0, 0};
  while (scanf("%63s", name) == 1) {
    if (scanf("%63s", text) != 1) strcpy(text, "(missing)");
    if (!strcmp(name, "table_t") || !strcmp(name, "table_T")) {
      int table = name[6] == 'T', n = atoi(text);
      double *dst = table ? p->tab_T : p->tab_t;
      if (n < 1 || n > MAXTAB) {
        fprintf(stderr, "error: stdin: %s = %s: expected a count of 1 to %d values, then the values\n", name, text,
                MAXTAB);
        return 1;
      }
      for (int i = 0; i < n; i++) {
        if (scanf("%63s", text) != 1) strcpy(text, "(missing)");
        if (!number(name, text, &dst[i])) return 1;
      }
      ntab[table] = n;
      continue;
    }
    int i = 0;
    while (i < nkeys && strcmp(keys[i].n, name)) i++;
    if (i == nkeys) {
      fprintf(stderr, "error: stdin: %s = %s: expected a parameter name of scipy_reference.load_parameters(), IL, "
                      "T0, cd, t_end, table_t or table_T\n", name, text);
      return 1;
    }
    if (!number(name, text, keys[i].v)) return 1;
  }
  if (ntab[0] < 1 || ntab[0] != ntab[1]) {
    fprintf(stderr, "error: stdin: table_t = %d values: expected a pump torque table, table_T of as many values\n",
            ntab[0]);
    return 1;
  }
  p->ntab = ntab[0];
  return 0;
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int cmp(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

int main(int argc, char **argv) {
  if (argc != 3) {
    fprintf(stderr, "error: argv: %d arguments: expected REPEATS SAMPLES (usage: takeoff REPEATS SAMPLES < params)\n",
            argc - 1);
    return 2;
  }
  int reps = atoi(argv[1]), ns = atoi(argv[2]);
  if (reps < 1 || ns < 2) {
    fprintf(stderr, "error: argv: %s = %s: expected REPEATS >= 1 and SAMPLES >= 2\n", reps < 1 ? "REPEATS" : "SAMPLES",
            reps < 1 ? argv[1] : argv[2]);
    return 2;
  }
  Params p;
  if (read_params(&p)) return 2;
  derive(&p);
  SUNContext ctx;
  if (SUNContext_Create(NULL, &ctx)) return 1;
  double *times = malloc(sizeof(double) * ns), *wall = malloc(sizeof(double) * reps);
  for (int i = 0; i < ns; i++) times[i] = i * (p.t_end / (ns - 1)); /* as numpy.linspace */
  times[ns - 1] = p.t_end;
  Samples s;
  double **cols[] = {&s.t, &s.wp, &s.wt, &s.ws, &s.Q, &s.Tp, &s.Tt, &s.Ts, &s.Ploss};
  Stats st;
  int status = 0;
  for (int r = -1; r < reps; r++) { /* r = -1: warm-up */
    double t0 = now();
    for (int c = 0; c < 9; c++) *cols[c] = malloc(sizeof(double) * ns);
    status = run(&p, ctx, times, ns, &s, &st);
    double t1 = now();
    if (status) break;
    if (r >= 0) wall[r] = t1 - t0;
    if (r < reps - 1)
      for (int c = 0; c < 9; c++) free(*cols[c]);
  }
  if (status == 4) {
    fprintf(stderr, "error: stdin: table_T = %g: expected a first pump torque that the converter absorbs at a "
                    "steady state (positive)\n", p.tab_T[0]);
    return 2;
  }
  if (status) { /* not the user's input: exit 1 */
    fprintf(stderr, status == 3 ? "error: the flow reached zero at t = %g s: flow reversal is not modelled by this peer\n"
                                : "error: CVODE failed at t = %g s\n", last_t);
    return 1;
  }
  qsort(wall, reps, sizeof(double), cmp);
  printf("timing %.9e %.9e %d\n", wall[reps / 2], wall[0], reps);
  printf("stats %ld %ld %ld %ld %ld\n", st.steps, st.rhs, st.jac, st.lu, st.groots);
  for (int e = 0; e < st.nevents && e < 16; e++)
    printf("event %.9f %s\n", st.ev_t[e], st.ev_kind[e] ? "stator-lock" : "stator-release");
  for (int k = 0; k < ns; k++)
    printf("sample %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", s.t[k], s.wp[k], s.wt[k], s.ws[k],
           s.Q[k], s.Tp[k], s.Tt[k], s.Ts[k], s.Ploss[k]);
  SUNContext_Free(&ctx);
  return 0;
}
