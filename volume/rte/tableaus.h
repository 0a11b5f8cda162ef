#pragma once
// Butcher tableaus as data. One generic driver (explicit_rk.h) runs all of them.
// `b` is the solution that is propagated; `bHat` the embedded one (error = h (b - bHat) k).
#include <array>
#include <cstddef>

namespace lvox::rte {

template <std::size_t S>
struct ButcherTableau {
  static constexpr std::size_t kStages = S;
  std::array<double, S> c;
  std::array<std::array<double, S>, S> a;  // strictly lower triangular
  std::array<double, S> b;
  std::array<double, S> bHat;  // all zero for fixed-step methods
  int order;                   // order of b
  int errorOrder;              // order of bHat (the controller's exponent uses the lower one)
};

// Explicit Euler.
inline constexpr ButcherTableau<1> kEulerTableau{{0.0}, {{{0.0}}}, {1.0}, {0.0}, 1, 0};

// Explicit midpoint (the "RK2" of Munoz 2012).
inline constexpr ButcherTableau<2> kMidpointTableau{
    {0.0, 0.5}, {{{0.0, 0.0}, {0.5, 0.0}}}, {0.0, 1.0}, {0.0, 0.0}, 2, 0};

// Classic RK4. Stages 2 and 3 share t + h/2, so the linear RTE needs 2 new evaluations.
inline constexpr ButcherTableau<4> kRk4Tableau{
    {0.0, 0.5, 0.5, 1.0},
    {{{0, 0, 0, 0}, {0.5, 0, 0, 0}, {0, 0.5, 0, 0}, {0, 0, 1.0, 0}}},
    {1.0 / 6, 1.0 / 3, 1.0 / 3, 1.0 / 6},
    {0, 0, 0, 0},
    4,
    0};

// Heun (order 2, propagated: local extrapolation) with Euler (order 1) embedded.
inline constexpr ButcherTableau<2> kHeunEulerTableau{
    {0.0, 1.0}, {{{0.0, 0.0}, {1.0, 0.0}}}, {0.5, 0.5}, {1.0, 0.0}, 2, 1};

// Bogacki-Shampine 3(2): propagates order 3 (as MATLAB's ode23); FSAL.
inline constexpr ButcherTableau<4> kBs23Tableau{
    {0.0, 0.5, 0.75, 1.0},
    {{{0, 0, 0, 0}, {0.5, 0, 0, 0}, {0, 0.75, 0, 0}, {2.0 / 9, 1.0 / 3, 4.0 / 9, 0}}},
    {2.0 / 9, 1.0 / 3, 4.0 / 9, 0.0},
    {7.0 / 24, 1.0 / 4, 1.0 / 3, 1.0 / 8},
    3,
    2};

// Runge-Kutta-Fehlberg 4(5): propagates the 4th-order solution, Fehlberg's design.
inline constexpr ButcherTableau<6> kRkf45Tableau{
    {0.0, 1.0 / 4, 3.0 / 8, 12.0 / 13, 1.0, 1.0 / 2},
    {{{0, 0, 0, 0, 0, 0},
      {1.0 / 4, 0, 0, 0, 0, 0},
      {3.0 / 32, 9.0 / 32, 0, 0, 0, 0},
      {1932.0 / 2197, -7200.0 / 2197, 7296.0 / 2197, 0, 0, 0},
      {439.0 / 216, -8.0, 3680.0 / 513, -845.0 / 4104, 0, 0},
      {-8.0 / 27, 2.0, -3544.0 / 2565, 1859.0 / 4104, -11.0 / 40, 0}}},
    {25.0 / 216, 0, 1408.0 / 2565, 2197.0 / 4104, -1.0 / 5, 0},
    {16.0 / 135, 0, 6656.0 / 12825, 28561.0 / 56430, -9.0 / 50, 2.0 / 55},
    4,
    5};

// Cash-Karp 5(4): propagates the 5th-order solution (as Numerical Recipes).
inline constexpr ButcherTableau<6> kCashKarpTableau{
    {0.0, 1.0 / 5, 3.0 / 10, 3.0 / 5, 1.0, 7.0 / 8},
    {{{0, 0, 0, 0, 0, 0},
      {1.0 / 5, 0, 0, 0, 0, 0},
      {3.0 / 40, 9.0 / 40, 0, 0, 0, 0},
      {3.0 / 10, -9.0 / 10, 6.0 / 5, 0, 0, 0},
      {-11.0 / 54, 5.0 / 2, -70.0 / 27, 35.0 / 27, 0, 0},
      {1631.0 / 55296, 175.0 / 512, 575.0 / 13824, 44275.0 / 110592, 253.0 / 4096, 0}}},
    {37.0 / 378, 0, 250.0 / 621, 125.0 / 594, 0, 512.0 / 1771},
    {2825.0 / 27648, 0, 18575.0 / 48384, 13525.0 / 55296, 277.0 / 14336, 1.0 / 4},
    5,
    4};

// Dormand-Prince 5(4): propagates order 5 (local extrapolation); FSAL.
inline constexpr ButcherTableau<7> kDopri5Tableau{
    {0.0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1.0, 1.0},
    {{{0, 0, 0, 0, 0, 0, 0},
      {1.0 / 5, 0, 0, 0, 0, 0, 0},
      {3.0 / 40, 9.0 / 40, 0, 0, 0, 0, 0},
      {44.0 / 45, -56.0 / 15, 32.0 / 9, 0, 0, 0, 0},
      {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729, 0, 0, 0},
      {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656, 0, 0},
      {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84, 0}}},
    {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84, 0},
    {5179.0 / 57600, 0, 7571.0 / 16695, 393.0 / 640, -92097.0 / 339200, 187.0 / 2100, 1.0 / 40},
    5,
    4};

// Verner 6(5), the pair of DVERK (Hull, Enright & Jackson 1976). We propagate the
// 6th-order solution (local extrapolation); the 5th-order one only estimates the error.
inline constexpr ButcherTableau<8> kVerner56Tableau{
    {0.0, 1.0 / 6, 4.0 / 15, 2.0 / 3, 5.0 / 6, 1.0, 1.0 / 15, 1.0},
    {{{0, 0, 0, 0, 0, 0, 0, 0},
      {1.0 / 6, 0, 0, 0, 0, 0, 0, 0},
      {4.0 / 75, 16.0 / 75, 0, 0, 0, 0, 0, 0},
      {5.0 / 6, -8.0 / 3, 5.0 / 2, 0, 0, 0, 0, 0},
      {-165.0 / 64, 55.0 / 6, -425.0 / 64, 85.0 / 96, 0, 0, 0, 0},
      {12.0 / 5, -8.0, 4015.0 / 612, -11.0 / 36, 88.0 / 255, 0, 0, 0},
      {-8263.0 / 15000, 124.0 / 75, -643.0 / 680, -81.0 / 250, 2484.0 / 10625, 0, 0, 0},
      {3501.0 / 1720, -300.0 / 43, 297275.0 / 52632, -319.0 / 2322, 24068.0 / 84065, 0,
       3850.0 / 26703, 0}}},
    {3.0 / 40, 0, 875.0 / 2244, 23.0 / 72, 264.0 / 1955, 0, 125.0 / 11592, 43.0 / 616},
    {13.0 / 160, 0, 2375.0 / 5984, 5.0 / 16, 12.0 / 85, 3.0 / 44, 0, 0},
    6,
    5};

}  // namespace lvox::rte
