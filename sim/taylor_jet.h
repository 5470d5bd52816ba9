#pragma once
/// @file taylor_jet.h
/// @brief Truncated Taylor polynomial arithmetic (forward-mode automatic differentiation of any
/// order) used to obtain exact time derivatives of the analytic trajectory.
///
/// A jet of order N represents f(t0 + h) = Σ_{k=0..N} c_k h^k + O(h^{N+1}), i.e. c_k = f^(k)(t0)/k!.
/// Sums are coefficient-wise; products are Cauchy products (fg)_k = Σ_{i=0..k} f_i g_{k−i};
/// quotients, square roots, sines and cosines follow the classic recurrences:
///   h = f/g:     h_k = (f_k − Σ_{i=1..k} g_i h_{k−i}) / g_0
///   h = √f:      h_k = (f_k − Σ_{i=1..k−1} h_i h_{k−i}) / (2 h_0)
///   s = sin f, c = cos f:  s_k = (1/k) Σ_{i=1..k} i f_i c_{k−i},  c_k = −(1/k) Σ_{i=1..k} i f_i s_{k−i}
///   h = atan2(y, x):  h′ = (x y′ − y x′)/(x² + y²) =: q,  h_k = q_{k−1} / k
/// Derivatives are read back as f^(k)(t0) = k! · c_k (`derivative(k)`).

#include <array>
#include <cmath>

namespace meshnav::sim {

template <int N>
struct TaylorJet {
  static_assert(N >= 0, "jet order must be non-negative");
  std::array<double, N + 1> c{};  ///< normalized Taylor coefficients c_k = f^(k)/k!

  /// Constant function f(t) = value.
  static TaylorJet constant(double value) {
    TaylorJet j;
    j.c[0] = value;
    return j;
  }
  /// The independent variable t at t0: c = [t0, 1, 0, ...].
  static TaylorJet variable(double t0) {
    TaylorJet j;
    j.c[0] = t0;
    if constexpr (N >= 1) j.c[1] = 1.0;
    return j;
  }
  double value() const { return c[0]; }
  /// k-th time derivative f^(k)(t0) = k! · c_k.
  double derivative(int k) const {
    double fact = 1.0;
    for (int i = 2; i <= k; ++i) fact *= i;
    return fact * c[k];
  }
  /// Jet of the M-th derivative, truncated to order N − M: (f^(M))_k = c_{k+M} (k+M)!/k!.
  template <int M>
  TaylorJet<N - M> derived() const {
    static_assert(M >= 0 && M <= N, "cannot differentiate beyond the jet order");
    TaylorJet<N - M> d;
    for (int k = 0; k <= N - M; ++k) {
      double f = 1.0;
      for (int i = k + 1; i <= k + M; ++i) f *= i;
      d.c[k] = c[k + M] * f;
    }
    return d;
  }
  /// The same function at a lower order (drops the higher coefficients).
  template <int M>
  TaylorJet<M> truncated() const {
    static_assert(M <= N, "cannot raise the jet order");
    TaylorJet<M> d;
    for (int k = 0; k <= M; ++k) d.c[k] = c[k];
    return d;
  }

  TaylorJet& operator+=(const TaylorJet& o) {
    for (int k = 0; k <= N; ++k) c[k] += o.c[k];
    return *this;
  }
  TaylorJet& operator-=(const TaylorJet& o) {
    for (int k = 0; k <= N; ++k) c[k] -= o.c[k];
    return *this;
  }
  TaylorJet& operator*=(double s) {
    for (auto& v : c) v *= s;
    return *this;
  }
};

template <int N>
TaylorJet<N> operator+(TaylorJet<N> a, const TaylorJet<N>& b) { return a += b; }
template <int N>
TaylorJet<N> operator-(TaylorJet<N> a, const TaylorJet<N>& b) { return a -= b; }
template <int N>
TaylorJet<N> operator-(TaylorJet<N> a) { return a *= -1.0; }
template <int N>
TaylorJet<N> operator+(TaylorJet<N> a, double s) { a.c[0] += s; return a; }
template <int N>
TaylorJet<N> operator+(double s, TaylorJet<N> a) { a.c[0] += s; return a; }
template <int N>
TaylorJet<N> operator-(TaylorJet<N> a, double s) { a.c[0] -= s; return a; }
template <int N>
TaylorJet<N> operator-(double s, const TaylorJet<N>& a) { return (-a) + s; }
template <int N>
TaylorJet<N> operator*(TaylorJet<N> a, double s) { return a *= s; }
template <int N>
TaylorJet<N> operator*(double s, TaylorJet<N> a) { return a *= s; }

/// Cauchy product.
template <int N>
TaylorJet<N> operator*(const TaylorJet<N>& a, const TaylorJet<N>& b) {
  TaylorJet<N> r;
  for (int k = 0; k <= N; ++k) {
    double s = 0.0;
    for (int i = 0; i <= k; ++i) s += a.c[i] * b.c[k - i];
    r.c[k] = s;
  }
  return r;
}

template <int N>
TaylorJet<N> operator/(const TaylorJet<N>& f, const TaylorJet<N>& g) {
  TaylorJet<N> h;
  for (int k = 0; k <= N; ++k) {
    double s = f.c[k];
    for (int i = 1; i <= k; ++i) s -= g.c[i] * h.c[k - i];
    h.c[k] = s / g.c[0];
  }
  return h;
}

template <int N>
TaylorJet<N> operator/(TaylorJet<N> f, double s) { return f *= (1.0 / s); }

template <int N>
TaylorJet<N> sqrt(const TaylorJet<N>& f) {
  TaylorJet<N> h;
  h.c[0] = std::sqrt(f.c[0]);
  for (int k = 1; k <= N; ++k) {
    double s = f.c[k];
    for (int i = 1; i <= k - 1; ++i) s -= h.c[i] * h.c[k - i];
    h.c[k] = s / (2.0 * h.c[0]);
  }
  return h;
}

/// sin and cos of a jet computed together (their recurrences are coupled).
template <int N>
void sincos(const TaylorJet<N>& f, TaylorJet<N>& s, TaylorJet<N>& co) {
  s.c[0] = std::sin(f.c[0]);
  co.c[0] = std::cos(f.c[0]);
  for (int k = 1; k <= N; ++k) {
    double ss = 0.0, cc = 0.0;
    for (int i = 1; i <= k; ++i) {
      ss += i * f.c[i] * co.c[k - i];
      cc += i * f.c[i] * s.c[k - i];
    }
    s.c[k] = ss / k;
    co.c[k] = -cc / k;
  }
}

template <int N>
TaylorJet<N> sin(const TaylorJet<N>& f) {
  TaylorJet<N> s, c;
  sincos(f, s, c);
  return s;
}

template <int N>
TaylorJet<N> cos(const TaylorJet<N>& f) {
  TaylorJet<N> s, c;
  sincos(f, s, c);
  return c;
}

/// Four-quadrant arc tangent of y/x (the value in (−π, π]; derivatives from h′ = (x y′ − y x′)/(x² + y²)).
template <int N>
TaylorJet<N> atan2(const TaylorJet<N>& y, const TaylorJet<N>& x) {
  // Jets of y′ and x′; their top coefficient would need c_{N+1} and only feeds h_{N+1}: left 0.
  TaylorJet<N> dy, dx;
  for (int k = 0; k < N; ++k) {
    dy.c[k] = (k + 1) * y.c[k + 1];
    dx.c[k] = (k + 1) * x.c[k + 1];
  }
  const TaylorJet<N> q = (x * dy - y * dx) / (x * x + y * y);
  TaylorJet<N> h;
  h.c[0] = std::atan2(y.c[0], x.c[0]);
  for (int k = 1; k <= N; ++k) h.c[k] = q.c[k - 1] / k;
  return h;
}

}  // namespace meshnav::sim
