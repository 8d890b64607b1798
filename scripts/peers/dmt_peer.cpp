// Compiled DOP853 peer of afmdyn for the point-mass DMT model (issue 26, item 5).
//
// The model (afmdyn's point-mass structure with the DMT law, dimensionless: τ = ω₀t, lengths of
// A₀, forces of k A₀; docs/getting-started.md, the structural models and SI to groups):
//
//   z'' + α3 z' + z = α2 cos Ωτ + F_c(δ, δ̇),   δ = −V_T, δ̇ = −V_T',   V_T = z + α5
//
// (crates/afmdyn/src/params.rs `Structure::PointMass`, galerkin.rs `forcing_free`: M = K = 1,
// φ(1) = 1, C = α3, force drive α2 cos Ωτ; model.rs `v_t_at` with base amplitude 0 and
// `rhs_slice`: the free-region matrices plus the tip force in both regions). The DMT law
// (contact.rs `TipSample::force`, `ContactLaw::Dmt`; Derjaguin, Muller & Toporov, J. Colloid
// Interface Sci. 53 (1975) 314; García & San Paulo, Phys. Rev. B 60 (1999) 4961), with the
// tip–sample distance d = V_T + ã₀ (`ContactLaw::distance_offset`):
//
//   free     (V_T > 0, d > ã₀):  F_c = −H̃/d²
//   contact  (V_T ≤ 0, d ≤ ã₀):  F_c = −H̃/ã₀² + α4 δ^{3/2} + α6 √δ δ̇
//
// The law switches form at V_T = 0 (afmdyn's guard, model.rs `guard_value`: σ V_T with σ = +1 in
// free flight, −1 in contact); the force is continuous there, its second derivative is not.
//
// The integrator is our own DOP853: the explicit Runge–Kutta pair of order 8(5,3) with the
// order-7 dense output of Dormand & Prince (Hairer, Nørsett & Wanner, Solving Ordinary
// Differential Equations I, 2nd ed., Springer 1993, §II.5 (DOP853, Table 5.4), §II.6 (CONTD8),
// §II.4 (HINIT)); coefficients as in Hairer's Fortran dop853.f (1993), transcribed from
// crates/afmdyn/src/integrate/dop853.rs. Step-size control as dop853.f with its defaults:
// err = |h| e₅/√(n (e₅ + 0.01 e₃)), sk = atol + rtol max(|y₀|, |y₁|), h_new = h / fac with
// fac = clamp(err^{1/8}/0.9, 1/6, 1/0.333) (BETA = 0: no Lund stabilisation), after a rejection
// h_new = h / min(1/0.333, err^{1/8}/0.9) and the next accepted step does not grow; the last step
// before an output time is stretched to it when within 1 % (the `x + 1.01 h > xend` rule).
// h_max = T/8 as afmdyn (adaptive.rs `new_stepper`).
//
// Events: after every accepted step [t0, t1] the guard g is checked as afmdyn does
// (adaptive.rs `find_zero`): a crossing when g(t1) < −ε, or when g has an interior minimum
// (g' from − to +, located on the dense output) below −ε, ε = 1e-12 (1 + |α5|) (model.rs
// `guard_tolerance`). The leftmost zero is bracketed (from the last point with g > 0, after an
// event the first maximum of g) and located on the dense output by safeguarded Newton
// (bisection when a Newton step leaves the bracket); it is then polished by Newton on g(τ) with
// the state at every iterate integrated afresh from the step's start (error-controlled), so the
// event time is exact to the integration tolerance, not the interpolant. The integration
// restarts there in the other region (FSAL stage recomputed, same proposed step size).
//
// Observables (afmdyn analysis/observables.rs `observe`): over an integer number of drive
// periods, on every accepted step piece (cut at events and period ends) a 16-point
// Gauss–Legendre rule on the dense output integrates z sin θ, z cos θ and z, θ = Ωτ + ψ,
// ψ = π/2 (params.rs `drive_phase` for the point mass). s = (2/T_w)∫z sin θ, c = (2/T_w)∫z cos θ,
// A₁ = hypot(s, c), φ = atan2(−c, s) wrapped to (−π/2, 3π/2]: z ≈ ⟨z⟩ + A₁ sin(θ − φ).
//
//   g++ -O3 -march=native -std=c++17 -o dmt_peer dmt_peer.cpp
//   dmt_peer alpha2=… alpha3=… alpha4=… alpha5=… alpha6=… omega=… hamaker=… a0=…
//            [tol=1e-12] [transient=6000] [record=100] [periods=3000] [reps=3]
//
// From rest at τ = 0 it integrates `transient` periods, then `record` periods with the
// quadrature (agreement); then times `periods` periods, best of `reps`, from rest (as
// `afmdyn simulate` runs), from the state after the transient (the steady orbit), and from rest
// with the quadrature on every step, landing on every period end as afmdyn's Poincaré section
// does. Prints one JSON line.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>

namespace {

constexpr int N = 2;  // state (z, z')
constexpr double PI = 3.14159265358979323846;
constexpr double EPS = 2.220446049250313e-16;

enum Region { FREE = 0, CONTACT = 1 };

// ---------------------------------------------------------------------------------------------
// The model
// ---------------------------------------------------------------------------------------------

struct Model {
  double alpha2 = 0, alpha3 = 0, alpha4 = 0, alpha5 = 0, alpha6 = 0, omega = 1;
  double hamaker = 0;  // H̃
  double a0 = 0;       // ã₀, the intermolecular distance

  double period() const { return 2.0 * PI / omega; }

  // V_T = W + α5 (eq. 8 for the point mass, whose base does not move): model.rs `v_t_at`.
  double v_t(const double* y) const { return y[0] + alpha5; }

  // F_c(δ, δ̇), repulsive positive: contact.rs `TipSample::force`, `ContactLaw::Dmt`.
  double force(Region r, double delta, double rate) const {
    if (r == CONTACT) {
      const double d = std::max(delta, 0.0);
      const double s = std::sqrt(d);
      return -hamaker / (a0 * a0) + alpha4 * d * s + alpha6 * s * rate;
    }
    const double d = a0 - delta;  // d = ã₀ + V_T > ã₀
    return -hamaker / (d * d);
  }

  // ż of region r: model.rs `rhs_slice` for the point mass (M = K = 1, C = α3, F^I = α2 cos Ωτ,
  // φ(1) = 1), the tip force F_c(−V_T, −V_T') added to the acceleration.
  void rhs(Region r, double t, const double* y, double* dy) const {
    const double fc = force(r, -v_t(y), -y[1]);
    dy[0] = y[1];
    dy[1] = alpha2 * std::cos(omega * t) - y[0] - alpha3 * y[1] + fc;
  }

  // The guard σ V_T, positive inside the region (model.rs `guard_value`), and its rate σ V_T'.
  double guard(Region r, const double* y) const { return (r == FREE ? 1.0 : -1.0) * v_t(y); }
  double guard_rate(Region r, const double* y) const { return (r == FREE ? 1.0 : -1.0) * y[1]; }
  // The round-off dead band ε of the guard: model.rs `guard_tolerance` (base amplitude 0).
  double guard_tolerance() const { return 1e-12 * (1.0 + std::fabs(alpha5)); }
  // Region at a start: contact when V_T < 0 or V_T = 0 moving in (model.rs `mode_at`).
  Region region_at(const double* y) const {
    const double v = v_t(y);
    return (v < 0.0 || (v == 0.0 && y[1] <= 0.0)) ? CONTACT : FREE;
  }
};

// ---------------------------------------------------------------------------------------------
// DOP853 (coefficients of dop853.f, as in crates/afmdyn/src/integrate/dop853.rs)
// ---------------------------------------------------------------------------------------------

const double C[16] = {0.0, 5.260015195876773E-2, 7.890022793815160E-2, 1.183503419072274E-1,
                      2.816496580927726E-1, 3.333333333333333E-1, 0.25, 3.076923076923077E-1,
                      6.512820512820513E-1, 0.6, 8.571428571428571E-1, 1.0, 1.0, 0.1, 0.2,
                      7.777777777777778E-1};

// a_ij, row i uses stages j < i; rows 13–15 are the dense output's extra stages (12 is f(t+h)).
const double A[16][15] = {
    {0},
    {5.260015195876773E-2},
    {1.97250569845379E-2, 5.91751709536137E-2},
    {2.958758547680685E-2, 0.0, 8.876275643042054E-2},
    {2.413651341592667E-1, 0.0, -8.845494793282861E-1, 9.24834003261792E-1},
    {3.7037037037037035E-2, 0.0, 0.0, 1.7082860872947386E-1, 1.2546768756682242E-1},
    {3.7109375E-2, 0.0, 0.0, 1.7025221101954405E-1, 6.021653898045596E-2, -1.7578125E-2},
    {3.709200011850479E-2, 0.0, 0.0, 1.7038392571223998E-1, 1.0726203044637328E-1,
     -1.5319437748624402E-2, 8.273789163814023E-3},
    {6.241109587160757E-1, 0.0, 0.0, -3.3608926294469414, -8.68219346841726E-1,
     2.759209969944671E1, 2.0154067550477894E1, -4.348988418106996E1},
    {4.7766253643826434E-1, 0.0, 0.0, -2.4881146199716677, -5.90290826836843E-1,
     2.1230051448181193E1, 1.5279233632882423E1, -3.328821096898486E1, -2.0331201708508627E-2},
    {-9.371424300859873E-1, 0.0, 0.0, 5.186372428844064, 1.0914373489967295,
     -8.149787010746927, -1.852006565999696E1, 2.2739487099350505E1, 2.4936055526796523,
     -3.0467644718982196},
    {2.273310147516538, 0.0, 0.0, -1.053449546673725E1, -2.0008720582248625,
     -1.79589318631188E1, 2.794888452941996E1, -2.8589982771350235, -8.87285693353063,
     1.2360567175794303E1, 6.433927460157636E-1},
    {0},
    {5.6167502283047954E-2, 0.0, 0.0, 0.0, 0.0, 0.0, 2.5350021021662483E-1,
     -2.462390374708025E-1, -1.2419142326381637E-1, 1.5329179827876568E-1,
     8.20105229563469E-3, 7.567897660545699E-3, -8.298E-3},
    {3.183464816350214E-2, 0.0, 0.0, 0.0, 0.0, 2.8300909672366776E-2, 5.3541988307438566E-2,
     -5.492374857139099E-2, 0.0, 0.0, -1.0834732869724932E-4, 3.825710908356584E-4,
     -3.4046500868740456E-4, 1.413124436746325E-1},
    {-4.2889630158379194E-1, 0.0, 0.0, 0.0, 0.0, -4.697621415361164, 7.683421196062599,
     4.06898981839711, 3.567271874552811E-1, 0.0, 0.0, 0.0, -1.3990241651590145E-3,
     2.9475147891527724, -9.15095847217987},
};

// weights of the order-8 solution (stages 1–12)
const double B[12] = {5.4293734116568765E-2, 0.0, 0.0, 0.0, 0.0, 4.450312892752409,
                      1.8915178993145003, -5.801203960010585, 3.111643669578199E-1,
                      -1.521609496625161E-1, 2.0136540080403034E-1, 4.471061572777259E-2};
// order-3 estimator err₃ = Σ b k − (bh₁ k₁ + bh₉ k₉ + bh₁₂ k₁₂)
const double BH1 = 2.440944881889764E-1, BH9 = 7.338466882816118E-1,
             BH12 = 2.2058823529411766E-2;
// order-5 estimator err₅ = Σ er k over stages 1, 6–12
const double ER[12] = {1.312004499419488E-2, 0.0, 0.0, 0.0, 0.0, -1.2251564463762044,
                       -4.957589496572502E-1, 1.6643771824549864, -3.5032884874997366E-1,
                       3.341791187130175E-1, 8.192320648511571E-2, -2.2355307863886294E-2};
// dense output cont₄…cont₇ = h Σ d_ij k_j over the 16 stages
const double D[4][16] = {
    {-8.428938276109013, 0.0, 0.0, 0.0, 0.0, 5.667149535193777E-1, -3.0689499459498917,
     2.38466765651207, 2.117034582445028, -8.71391583777973E-1, 2.2404374302607883,
     6.315787787694688E-1, -8.899033645133331E-2, 1.8148505520854727E1, -9.194632392478356,
     -4.436036387594894},
    {1.0427508642579134E1, 0.0, 0.0, 0.0, 0.0, 2.4228349177525817E2, 1.6520045171727028E2,
     -3.745467547226902E2, -2.2113666853125306E1, 7.733432668472264, -3.0674084731089398E1,
     -9.332130526430229, 1.5697238121770845E1, -3.1139403219565178E1, -9.35292435884448,
     3.581684148639408E1},
    {1.9985053242002433E1, 0.0, 0.0, 0.0, 0.0, -3.870373087493518E2, -1.8917813819516758E2,
     5.278081592054236E2, -1.157390253995963E1, 6.8812326946963, -1.0006050966910838,
     7.777137798053443E-1, -2.778205752353508, -6.019669523126412E1, 8.432040550667716E1,
     1.199229113618279E1},
    {-2.569393346270375E1, 0.0, 0.0, 0.0, 0.0, -1.5418974869023643E2, -2.315293791760455E2,
     3.576391179106141E2, 9.340532418362432E1, -3.745832313645163E1, 1.040996495089623E2,
     2.98402934266605E1, -4.353345659001114E1, 9.632455395918828E1, -3.917726167561544E1,
     -1.4972683625798564E2},
};

// dop853.f's defaults: SAFE, FAC1, FAC2 (FAC1 ≤ h_new/h ≤ FAC2), BETA = 0
constexpr double SAFE = 0.9, FAC1 = 0.333, FAC2 = 6.0;

struct Counts {
  long accepted = 0, rejected = 0, events = 0, polish_steps = 0, rhs = 0;
};

// One DOP853 stepper in one region (its vector field fixed), one step at a time.
struct Dop853 {
  const Model* m = nullptr;
  Region region = FREE;
  double rtol = 1e-12, atol = 1e-12, hmax = 1.0;
  double t = 0, h = 0, t_prev = 0, h_prev = 0;
  bool reject = false, dense_ready = false;
  double y[N] = {0}, y_prev[N] = {0};
  double k[16][N] = {{0}};   // stages of the attempt: k[0] = f(t, y) (FSAL)
  double ka[16][N] = {{0}};  // stages of the last accepted step (k[12] = f at its end)
  double cont[8][N] = {{0}};
  Counts* cnt = nullptr;

  void f(double tt, const double* yy, double* dy) {
    m->rhs(region, tt, yy, dy);
    ++cnt->rhs;
  }

  // start at (t0, y0) in region r; h0 ≤ 0: HINIT (Hairer et al. §II.4, dop853.f HINIT, order 8)
  void init(const Model* model, Region r, double t0, const double* y0, double h0, Counts* c) {
    m = model;
    region = r;
    cnt = c;
    t = t_prev = t0;
    std::memcpy(y, y0, sizeof y);
    std::memcpy(y_prev, y0, sizeof y);
    f(t, y, k[0]);
    reject = false;
    dense_ready = false;
    h = h0 > 0 ? std::min(h0, hmax) : hinit();
    h_prev = h;
    std::memcpy(ka, k, sizeof ka);
  }

  double hinit() {
    double dnf = 0, dny = 0;
    for (int i = 0; i < N; ++i) {
      const double sk = atol + rtol * std::fabs(y[i]);
      dnf += (k[0][i] / sk) * (k[0][i] / sk);
      dny += (y[i] / sk) * (y[i] / sk);
    }
    double hh = (dnf <= 1e-10 || dny <= 1e-10) ? 1e-6 : std::sqrt(dny / dnf) * 0.01;
    hh = std::min(hh, hmax);
    double y1[N], f1[N];
    for (int i = 0; i < N; ++i) y1[i] = y[i] + hh * k[0][i];
    f(t + hh, y1, f1);
    double der2 = 0;
    for (int i = 0; i < N; ++i) {
      const double sk = atol + rtol * std::fabs(y[i]);
      der2 += ((f1[i] - k[0][i]) / sk) * ((f1[i] - k[0][i]) / sk);
    }
    der2 = std::sqrt(der2) / hh;
    const double der12 = std::max(std::fabs(der2), std::sqrt(dnf));
    const double h1 = der12 <= 1e-15 ? std::max(1e-6, hh * 1e-3) : std::pow(0.01 / der12, 1.0 / 8.0);
    return std::min({100 * hh, h1, hmax});
  }

  // one attempt with step h; true when accepted (t, y advance, the interpolant covers the step)
  bool attempt() {
    double tmp[N];
    for (int s = 1; s < 12; ++s) {
      for (int i = 0; i < N; ++i) {
        double acc = 0;
        for (int j = 0; j < s; ++j) acc += A[s][j] * k[j][i];
        tmp[i] = y[i] + h * acc;
      }
      f(t + C[s] * h, tmp, k[s]);
    }
    double y1[N], e5 = 0, e3 = 0;
    for (int i = 0; i < N; ++i) {
      double bk = 0, er = 0;
      for (int j = 0; j < 12; ++j) {
        bk += B[j] * k[j][i];
        er += ER[j] * k[j][i];
      }
      y1[i] = y[i] + h * bk;
      const double sk = atol + rtol * std::max(std::fabs(y[i]), std::fabs(y1[i]));
      const double err3 = bk - BH1 * k[0][i] - BH9 * k[8][i] - BH12 * k[11][i];
      e5 += (er / sk) * (er / sk);
      e3 += (err3 / sk) * (err3 / sk);
    }
    double deno = e5 + 0.01 * e3;
    if (deno <= 0) deno = 1;
    const double err = std::fabs(h) * e5 * std::sqrt(1.0 / (deno * N));
    const double fac11 = std::pow(err, 1.0 / 8.0);
    if (err <= 1.0 && std::isfinite(err)) {
      double hnew = h / std::max(1.0 / FAC2, std::min(1.0 / FAC1, fac11 / SAFE));
      f(t + h, y1, k[12]);
      ++cnt->accepted;
      hnew = std::min(hnew, hmax);
      if (reject) hnew = std::min(hnew, h);
      reject = false;
      std::memcpy(ka, k, sizeof ka);
      std::memcpy(y_prev, y, sizeof y);
      std::memcpy(y, y1, sizeof y);
      t_prev = t;
      h_prev = h;
      t = t + h;
      std::memcpy(k[0], k[12], sizeof k[0]);  // FSAL
      dense_ready = false;
      h = hnew;
      return true;
    }
    ++cnt->rejected;
    reject = true;
    h = std::isfinite(err) ? h / std::min(1.0 / FAC1, fac11 / SAFE) : h * FAC1;
    return false;
  }

  // one accepted step, not past t_end (landing on it when within 1 %: dop853.f's LAST rule);
  // after landing the step size chosen before the cut is kept (as afmdyn's `advance`)
  void step(double t_end) {
    const double h_nat = h;
    bool cut = false;
    if (t + 1.01 * h >= t_end) {
      h = t_end - t;
      cut = true;
    }
    for (int tries = 0; tries < 1000; ++tries) {
      if (!(h > 0) || h < 1e-14 * h_prev) throw std::runtime_error("DOP853 step size underflow");
      if (attempt()) {
        if (cut && t >= t_end - 4 * EPS * (1 + std::fabs(t_end))) {
          t = t_end;
          h = std::max(h_nat, h);
        }
        return;
      }
      if (cut && h > t_end - t) h = t_end - t;
    }
    throw std::runtime_error("1000 rejected steps in a row");
  }

  // the dense output (dop853.f CONTD8) of the last accepted step: 3 more stages, then cont₀…₇
  void form_dense() {
    const double hh = h_prev;
    double tmp[N];
    for (int s = 13; s < 16; ++s) {
      for (int i = 0; i < N; ++i) {
        double acc = 0;
        for (int j = 0; j < s; ++j) acc += A[s][j] * ka[j][i];
        tmp[i] = y_prev[i] + hh * acc;
      }
      f(t_prev + C[s] * hh, tmp, ka[s]);
    }
    for (int i = 0; i < N; ++i) {
      const double ydiff = y[i] - y_prev[i];
      const double bspl = hh * ka[0][i] - ydiff;
      cont[0][i] = y_prev[i];
      cont[1][i] = ydiff;
      cont[2][i] = bspl;
      cont[3][i] = ydiff - hh * ka[12][i] - bspl;
      for (int r = 0; r < 4; ++r) {
        double acc = 0;
        for (int j = 0; j < 16; ++j) acc += D[r][j] * ka[j][i];
        cont[4 + r][i] = hh * acc;
      }
    }
    dense_ready = true;
  }

  // the order-7 interpolant of the last accepted step at tt
  void interpolate(double tt, double* out) {
    if (tt >= t) {
      std::memcpy(out, y, sizeof y);
      return;
    }
    if (tt <= t_prev) {
      std::memcpy(out, y_prev, sizeof y);
      return;
    }
    if (!dense_ready) form_dense();
    const double s = (tt - t_prev) / h_prev, s1 = 1.0 - s;
    for (int i = 0; i < N; ++i) {
      const double conpar = cont[4][i] + s * (cont[5][i] + s1 * (cont[6][i] + s * cont[7][i]));
      out[i] = cont[0][i] + s * (cont[1][i] + s1 * (cont[2][i] + s * (cont[3][i] + s1 * conpar)));
    }
  }
};

// ---------------------------------------------------------------------------------------------
// Event location and the driver
// ---------------------------------------------------------------------------------------------

// Root of a function on [a, b] with value and derivative `fd(t, &v, &dv)`, v(a) and v(b) of
// opposite signs: Newton from the end with the smaller |v|, bisection whenever a Newton step
// leaves the bracket or |v| did not halve in the last iterate; stops when the update or the
// bracket is below 4 ulp.
template <class FD>
double safeguarded_newton(double a, double fa, double b, double fb, FD fd) {
  if (fa == 0) return a;
  if (fb == 0) return b;
  double t = std::fabs(fa) < std::fabs(fb) ? a : b;
  double v_prev = INFINITY;
  for (int it = 0; it < 200; ++it) {
    double v, dv;
    fd(t, &v, &dv);
    if (v == 0) return t;
    if ((v > 0) == (fa > 0)) {
      a = t;
      fa = v;
    } else {
      b = t;
      fb = v;
    }
    const double lo = std::min(a, b), hi = std::max(a, b), mid = 0.5 * (a + b);
    double next = dv != 0 ? t - v / dv : mid;
    if (!(next > lo && next < hi) || std::fabs(v) > 0.5 * v_prev) next = mid;
    v_prev = std::fabs(v);
    const double small = 4 * EPS * (1 + std::fabs(t));
    if (std::fabs(next - t) <= small || hi - lo <= small) return next;
    t = next;
  }
  return t;
}

struct Run {
  Model m;
  double tol = 1e-12;
  Counts cnt;
  Dop853 st;
  bool just_switched = true;
  // quadrature (when on): ∫ z sin θ, ∫ z cos θ, ∫ z over the recorded window
  bool quad = false;
  double q_sin = 0, q_cos = 0, q_mean = 0;
  double gl_x[16], gl_w[16];

  explicit Run(const Model& model, double tolerance) : m(model), tol(tolerance) {
    st.rtol = st.atol = tol;
    st.hmax = m.period() / 8.0;
    gauss_legendre();
  }

  // nodes and weights of the 16-point Gauss–Legendre rule on [−1, 1] (Newton on P₁₆)
  void gauss_legendre() {
    const int n = 16;
    for (int i = 0; i < n; ++i) {
      double x = std::cos(PI * (i + 0.75) / (n + 0.5)), dp = 0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1, p1 = x;
        for (int k = 2; k <= n; ++k) {
          const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = n * (x * p1 - p0) / (x * x - 1);
        const double dx = p1 / dp;
        x -= dx;
        if (std::fabs(dx) < 1e-16) break;
      }
      gl_x[i] = x;
      gl_w[i] = 2 / ((1 - x * x) * dp * dp);
    }
  }

  void start(double t0, const double* y0, double h0) {
    st.init(&m, m.region_at(y0), t0, y0, h0, &cnt);
    just_switched = true;
  }

  // (g, g') on the dense output of the last accepted step
  void guard_on(double tt, double* g, double* dg) {
    double z[N];
    st.interpolate(tt, z);
    *g = m.guard(st.region, z);
    *dg = m.guard_rate(st.region, z);
  }

  // τ of the extremum of g (root of g') in [a, b], g'(a), g'(b) of opposite signs; g'' from the
  // vector field at the interpolated state
  double extremum(double a, double dga, double b, double dgb) {
    auto fd = [&](double tt, double* v, double* dv) {
      double z[N], dz[N];
      st.interpolate(tt, z);
      m.rhs(st.region, tt, z, dz);
      const double sg = st.region == FREE ? 1.0 : -1.0;
      *v = sg * z[1];
      *dv = sg * dz[1];
    };
    return safeguarded_newton(a, dga, b, dgb, fd);
  }

  // the leftmost guard zero in (t0, t1] on the dense output, or NaN (adaptive.rs `find_zero`)
  double find_zero(double t0, double t1) {
    const double dead = m.guard_tolerance();
    const double g0 = m.guard(st.region, st.y_prev), dg0 = m.guard_rate(st.region, st.y_prev);
    const double g1 = m.guard(st.region, st.y), dg1 = m.guard_rate(st.region, st.y);
    double tb = NAN, gb = 0;
    if (g1 < -dead) {
      tb = t1;
      gb = g1;
    } else if (dg0 < 0 && dg1 > 0) {  // an interior minimum: a dip that returns in the step
      const double tm = extremum(t0, dg0, t1, dg1);
      double gm, dgm;
      guard_on(tm, &gm, &dgm);
      if (gm < -dead) {
        tb = tm;
        gb = gm;
      }
    }
    if (std::isnan(tb)) return NAN;
    double ta = t0, ga = g0;
    if (just_switched || g0 <= 0) {
      // on the surface after an event: bracket from the first maximum of g before the bottom
      double gtb, dgtb;
      guard_on(tb, &gtb, &dgtb);
      if (dg0 > 0 && dgtb < 0) {
        ta = extremum(t0, dg0, tb, dgtb);
        double dga;
        guard_on(ta, &ga, &dga);
      }
      if (ga <= 0) return t0;  // never clearly inside the region
    }
    auto fd = [&](double tt, double* v, double* dv) { guard_on(tt, v, dv); };
    return safeguarded_newton(ta, ga, tb, std::min(gb, 0.0), fd);
  }

  // the state at ts integrated afresh from (t0, y0) in `region` (error-controlled)
  void integrate_to(Region region, double t0, const double* y0, double ts, double* out) {
    if (ts <= t0) {
      std::memcpy(out, y0, sizeof(double) * N);
      return;
    }
    Counts local;
    Dop853 s;
    s.rtol = s.atol = tol;
    s.hmax = st.hmax;
    s.init(&m, region, t0, y0, ts - t0, &local);
    while (s.t < ts) s.step(ts);
    std::memcpy(out, s.y, sizeof(double) * N);
    cnt.polish_steps += local.accepted + local.rejected;
    cnt.rhs += local.rhs;
  }

  // quadrature of the recorded integrals over [a, b] on the last step's dense output
  void piece(double a, double b) {
    if (!quad || b <= a) return;
    const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
    for (int i = 0; i < 16; ++i) {
      const double tt = mid + half * gl_x[i], w = half * gl_w[i];
      double z[N];
      st.interpolate(tt, z);
      const double th = m.omega * tt + 0.5 * PI;  // θ = Ωτ + ψ, ψ = π/2 (force drive)
      q_sin += w * z[0] * std::sin(th);
      q_cos += w * z[0] * std::cos(th);
      q_mean += w * z[0];
    }
  }

  // integrate to t_end exactly, locating and crossing every switching
  void advance(double t_end) {
    while (st.t < t_end) {
      const double t0 = st.t;
      double y0[N];
      std::memcpy(y0, st.y, sizeof y0);
      st.step(t_end);
      const double t1 = st.t;
      const double tz = find_zero(t0, t1);
      just_switched = false;
      if (std::isnan(tz)) {
        piece(t0, t1);
        continue;
      }
      // polish: Newton on g(τ), the state at each iterate integrated afresh from the step start
      double ts = tz, ys[N];
      integrate_to(st.region, t0, y0, ts, ys);
      for (int it = 0; it < 6; ++it) {
        const double g = m.guard(st.region, ys), rate = m.guard_rate(st.region, ys);
        if (rate == 0 || g == 0) break;
        const double next = std::clamp(ts - g / rate, t0, t1);
        if (std::fabs(next - ts) <= 4 * EPS * (1 + std::fabs(ts)) || next <= t0) break;
        ts = next;
        integrate_to(st.region, t0, y0, ts, ys);
      }
      piece(t0, ts);
      ++cnt.events;
      // restart in the other region at the crossing, with the step size the method proposed
      const Region next = st.region == FREE ? CONTACT : FREE;
      const double h = st.h;
      st.init(&m, next, ts, ys, h, &cnt);
      just_switched = true;
    }
  }
};

double wrap_phase(double p) {  // (−π/2, 3π/2], observables.rs `wrap_phase`
  double x = std::fmod(p, 2 * PI);
  if (x < 0) x += 2 * PI;
  if (x > 1.5 * PI) x -= 2 * PI;
  return x;
}

struct Timing {
  double us_per_period = 0;
  Counts c;
  double y_end[N] = {0};
};

// `periods` periods from (0, y0), landing on every period end; best wall time of `reps`
Timing time_run(const Model& m, double tol, const double* y0, long periods, int reps, bool quad) {
  Timing best;
  best.us_per_period = INFINITY;
  const double T = m.period();
  for (int r = 0; r < reps; ++r) {
    Run run(m, tol);
    run.quad = quad;
    const auto c0 = std::chrono::steady_clock::now();
    run.start(0.0, y0, 0.0);
    for (long p = 1; p <= periods; ++p) run.advance(p * T);
    const auto c1 = std::chrono::steady_clock::now();
    const double us = std::chrono::duration<double, std::micro>(c1 - c0).count() / periods;
    if (us < best.us_per_period) {
      best.us_per_period = us;
      best.c = run.cnt;
      std::memcpy(best.y_end, run.st.y, sizeof best.y_end);
    }
  }
  return best;
}

void print_counts(const char* name, const Timing& t, long periods) {
  const double p = static_cast<double>(periods);
  std::printf(
      "\"%s\":{\"us_per_period\":%.6g,\"periods\":%ld,\"accepted_per_period\":%.6g,"
      "\"rejected_per_period\":%.6g,\"events_per_period\":%.6g,\"polish_steps_per_period\":%.6g,"
      "\"rhs_per_period\":%.6g}",
      name, t.us_per_period, periods, t.c.accepted / p, t.c.rejected / p, t.c.events / p,
      t.c.polish_steps / p, t.c.rhs / p);
}

}  // namespace

int main(int argc, char** argv) {
  std::map<std::string, double> a = {{"tol", 1e-12},     {"transient", 6000}, {"record", 100},
                                     {"periods", 3000},  {"reps", 3}};
  const char* required[] = {"alpha2", "alpha3", "alpha4", "alpha5", "alpha6", "omega", "hamaker", "a0"};
  for (int i = 1; i < argc; ++i) {
    const char* eq = std::strchr(argv[i], '=');
    if (!eq) {
      std::fprintf(stderr, "argument '%s': expected key=value\n", argv[i]);
      return 2;
    }
    a[std::string(argv[i], static_cast<std::size_t>(eq - argv[i]))] = std::strtod(eq + 1, nullptr);
  }
  for (const char* k : required)
    if (!a.count(k)) {
      std::fprintf(stderr, "missing %s=...\n", k);
      return 2;
    }
  Model m;
  m.alpha2 = a["alpha2"];
  m.alpha3 = a["alpha3"];
  m.alpha4 = a["alpha4"];
  m.alpha5 = a["alpha5"];
  m.alpha6 = a["alpha6"];
  m.omega = a["omega"];
  m.hamaker = a["hamaker"];
  m.a0 = a["a0"];
  const double tol = a["tol"];
  const long transient = static_cast<long>(a["transient"]), record = static_cast<long>(a["record"]);
  const long periods = static_cast<long>(a["periods"]);
  const int reps = static_cast<int>(a["reps"]);
  const double T = m.period();
  const double rest[N] = {0.0, 0.0};

  try {
    // 1. agreement: transient from rest, then `record` periods with the quadrature
    Run run(m, tol);
    run.start(0.0, rest, 0.0);
    double z_prev[N] = {0, 0};
    for (long p = 1; p <= transient; ++p) {
      if (p == transient) std::memcpy(z_prev, run.st.y, sizeof z_prev);
      run.advance(p * T);
    }
    double z_T[N];
    std::memcpy(z_T, run.st.y, sizeof z_T);
    const double map_residual = std::hypot(z_T[0] - z_prev[0], z_T[1] - z_prev[1]);
    run.quad = true;
    for (long p = 1; p <= record; ++p) run.advance((transient + p) * T);
    const double tw = record * T;
    const double s = 2 * run.q_sin / tw, c = 2 * run.q_cos / tw;
    const double amplitude = std::hypot(s, c), phase = wrap_phase(std::atan2(-c, s));
    const double mean = run.q_mean / tw;

    // 2. timing: from rest (as `afmdyn simulate` runs) and on the steady orbit
    const Timing from_rest = time_run(m, tol, rest, periods, reps, false);
    const Timing steady = time_run(m, tol, z_T, periods, reps, false);
    // and from rest with the quadrature on every step (`afmdyn simulate` evaluates its energy
    // balance by Gauss–Legendre on the dense output of every step)
    const Timing recording = time_run(m, tol, rest, periods, reps, true);

    std::printf(
        "{\"tol\":%.3g,\"transient\":%ld,\"record\":%ld,\"amplitude\":%.17g,\"phase\":%.17g,"
        "\"mean\":%.17g,\"state\":[%.17g,%.17g],\"map_residual\":%.3g,",
        tol, transient, record, amplitude, phase, mean, z_T[0], z_T[1], map_residual);
    print_counts("recording", recording, periods);
    std::printf(",");
    print_counts("from_rest", from_rest, periods);
    std::printf(",\"from_rest_end\":[%.17g,%.17g],", from_rest.y_end[0], from_rest.y_end[1]);
    print_counts("steady", steady, periods);
    std::printf("}\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dmt_peer: %s\n", e.what());
    return 1;
  }
  return 0;
}
