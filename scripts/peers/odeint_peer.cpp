// Boost.Odeint peer of afmdyn: the same switched linear model (matrices exported by
// `cargo run --release -p afmdyn --example peer_export -- N model.json`), integrated as a C++
// user would: runge_kutta_dopri5 with dense output (atol = rtol = tol), the switching located on
// the dense output by TOMS748 (boost::math::tools::toms748_solve) on V_T = φ(1)ᵀa + α2 sin Ωτ + α5,
// and the stepper restarted in the new region at each switching (contact when V_T <= 0).
//
//   g++ -O3 -march=native -std=c++17 -o odeint_peer odeint_peer.cpp
//   odeint_peer model.json [tol=1e-12] [timed_periods=0|auto] [repetitions=5]
//
// Prints one JSON line: the state at τ_start + horizon (`z`), its agreement with afmdyn's exact
// state (`rel_err`: |z - z_ref| / |z_ref|, Euclidean norms), steps and switchings, the wall time
// of that run per forcing period; with timed_periods > 0 also the wall time per forcing period
// of a run of that many periods from τ_start (best of the repetitions); `auto`: as many periods
// as take about 0.3 s (at least 2).
#include <boost/math/tools/toms748_solve.hpp>
#include <boost/numeric/odeint.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

using state = std::vector<double>;
namespace ode = boost::numeric::odeint;

struct Region {
  std::vector<double> a;  // row-major 2N x 2N
  state b_const, b_sin, b_cos;
};

struct Model {
  std::size_t n = 0, dim = 0;
  double omega = 0, alpha2 = 0, alpha5 = 0, tau_start = 0, horizon = 0;
  state tip, z_start, z_ref;
  Region regions[2];  // 0 free, 1 contact

  double v_t(double tau, const state& z) const {
    double w = 0;
    for (std::size_t j = 0; j < n; ++j) w += tip[j] * z[j];
    return w + alpha2 * std::sin(omega * tau) + alpha5;
  }
};

static Region read_region(const nlohmann::json& j) {
  Region r;
  for (const auto& row : j.at("a"))
    for (const auto& v : row) r.a.push_back(v.get<double>());
  r.b_const = j.at("b_const").get<state>();
  r.b_sin = j.at("b_sin").get<state>();
  r.b_cos = j.at("b_cos").get<state>();
  return r;
}

static Model read_model(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error("cannot open " + path);
  nlohmann::json j = nlohmann::json::parse(f);
  Model m;
  m.n = j.at("n").get<std::size_t>();
  m.dim = 2 * m.n;
  m.omega = j.at("omega").get<double>();
  m.alpha2 = j.at("alpha2").get<double>();
  m.alpha5 = j.at("alpha5").get<double>();
  m.tau_start = j.at("tau_start").get<double>();
  m.horizon = j.at("horizon").get<double>();
  m.tip = j.at("tip").get<state>();
  m.z_start = j.at("z_start").get<state>();
  m.z_ref = j.at("z_ref").get<state>();
  m.regions[0] = read_region(j.at("free"));
  m.regions[1] = read_region(j.at("contact"));
  return m;
}

// ż = A z + b_const + b_sin sin Ωτ + b_cos cos Ωτ of one region
struct Rhs {
  const Model* m;
  const Region* r;
  void operator()(const state& z, state& dz, double tau) const {
    const double s = std::sin(m->omega * tau), c = std::cos(m->omega * tau);
    const std::size_t d = m->dim;
    const double* a = r->a.data();
    for (std::size_t i = 0; i < d; ++i) {
      double acc = r->b_const[i] + r->b_sin[i] * s + r->b_cos[i] * c;
      const double* row = a + i * d;
      for (std::size_t k = 0; k < d; ++k) acc += row[k] * z[k];
      dz[i] = acc;
    }
  }
};

struct Result {
  state z;
  long steps = 0, switchings = 0;
};

// Integrate from (tau0, z0) to tau_end.
static Result integrate(const Model& m, double tol, double tau0, const state& z0, double tau_end) {
  auto stepper = ode::make_dense_output(tol, tol, ode::runge_kutta_dopri5<state>());
  // the state at a switching or at tau_end by one dopri5 step from the start of the accepted step
  // (shorter than it, so within the tolerance): the 4th-order dense output of dopri5 alone limits
  // the agreement with the exact flow to about 1e-8 (relative, tau = 40) whatever the tolerance
  ode::runge_kutta_dopri5<state> single;
  auto restep = [&](const Rhs& rhs, double t0, double t, state& z) {
    z = stepper.previous_state();
    if (t > t0) {
      single.reset();  // FSAL: not the derivative stored by the last re-step
      single.do_step(rhs, z, t0, t - t0);
    }
  };
  int region = m.v_t(tau0, z0) <= 0 ? 1 : 0;
  // the guard g > 0 inside the region: V_T in free flight, -V_T in contact
  auto in_region = [](int r, double v) { return r == 0 ? v > 0 : v <= 0; };
  Result res;
  state z = z0, zt(m.dim);
  double tau = tau0, dt = 1e-3;
  stepper.initialize(z, tau, dt);
  while (true) {
    Rhs rhs{&m, &m.regions[region]};
    auto [t0, t1] = stepper.do_step(rhs);
    ++res.steps;
    const double tb = std::min(t1, tau_end);
    if (tb < t1) restep(rhs, t0, tb, zt);
    const state& zb = tb < t1 ? zt : stepper.current_state();
    if (!in_region(region, m.v_t(tb, zb))) {
      // switching in (t0, tb]: TOMS748 on V_T of the dense output
      state zs(m.dim);
      auto f = [&](double t) {
        stepper.calc_state(t, zs);
        return m.v_t(t, zs);
      };
      boost::uintmax_t iters = 200;
      const double fa = m.v_t(t0, stepper.previous_state()), fb = m.v_t(tb, zb);
      std::pair<double, double> br;
      if (fa == 0.0 || fb == 0.0 || (fa > 0) == (fb > 0)) {
        br = {tb, tb};  // sign already changed at the bracket end
      } else {
        br = boost::math::tools::toms748_solve(f, t0, tb, fa, fb,
                                               boost::math::tools::eps_tolerance<double>(52), iters);
      }
      // restart at the bracket end lying in the new region
      double te = br.second;
      if (!in_region(region, f(br.first))) te = br.first;
      if (te == t1)
        z = stepper.current_state();
      else
        restep(rhs, t0, te, z);
      region = 1 - region;
      ++res.switchings;
      tau = te;
      dt = stepper.current_time_step();
      stepper.initialize(z, tau, dt);
      if (tau >= tau_end) break;
      continue;
    }
    if (t1 >= tau_end) {
      z = zb;
      break;
    }
  }
  res.z = z;
  return res;
}

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: odeint_peer model.json [tol=1e-12] [timed_periods=0] [repetitions=5]\n";
    return 2;
  }
  const Model m = read_model(argv[1]);
  const double tol = argc > 2 ? std::stod(argv[2]) : 1e-12;
  const std::string periods_arg = argc > 3 ? argv[3] : "0";
  const int reps = argc > 4 ? std::stoi(argv[4]) : 5;
  const double period = 2 * std::acos(-1.0) / m.omega;

  auto h0 = std::chrono::steady_clock::now();
  const Result acc = integrate(m, tol, m.tau_start, m.z_start, m.tau_start + m.horizon);
  const double horizon_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - h0).count();
  double err = 0, scale = 0;
  for (std::size_t i = 0; i < m.dim; ++i) {
    err += (acc.z[i] - m.z_ref[i]) * (acc.z[i] - m.z_ref[i]);
    scale += m.z_ref[i] * m.z_ref[i];
  }
  const double horizon_us = horizon_wall * 1e6 / (m.horizon / period);
  nlohmann::json out = {{"peer", "odeint"},
                        {"n", m.n},
                        {"tol", tol},
                        {"abs_err", std::sqrt(err)},
                        {"rel_err", std::sqrt(err / scale)},
                        {"steps", acc.steps},
                        {"switchings", acc.switchings},
                        {"horizon_us_per_period", horizon_us},
                        {"z", acc.z}};
  const double periods = periods_arg == "auto"
                             ? std::max(2.0, std::round(0.3e6 / horizon_us))
                             : std::stod(periods_arg);
  if (periods > 0) {
    double best = std::numeric_limits<double>::infinity();
    double sink = 0;
    for (int r = 0; r < reps; ++r) {
      auto start = std::chrono::steady_clock::now();
      Result t = integrate(m, tol, m.tau_start, m.z_start, m.tau_start + periods * period);
      auto stop = std::chrono::steady_clock::now();
      sink += t.z[0];
      best = std::min(best, std::chrono::duration<double>(stop - start).count());
      out["steps_per_period"] = t.steps / periods;
      out["switchings_per_period"] = t.switchings / periods;
    }
    out["us_per_period"] = best * 1e6 / periods;
    out["timed_periods"] = periods;
    out["repetitions"] = reps;
    out["checksum"] = sink;  // the timed runs' results are used
  }
  std::cout << out.dump() << std::endl;
  return 0;
}
