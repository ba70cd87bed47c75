// det: the deterministic numeric layer (issue 46). Every transcendental function the simulation, the
// controllers, the metrics and the screening use comes from here, not from the C library: glibc picks
// FMA variants at run time on CPUs that have FMA, and WebAssembly's libm (musl) rounds other last bits.
// These are written in this tree (det.cpp: argument reduction and polynomials, + − × ÷ and sqrt
// only, compiled with -ffp-contract=off), so the same arguments give the same bits on every x86-64 CPU
// and in WebAssembly. Accuracy, speed and the reasons for this choice: docs/determinism.md.
// sqrt, floor, fmod, remainder, abs, copysign stay std:: (IEEE-exact everywhere).
// scripts/check-det fails when a std:: transcendental appears outside this folder and physics/bullet.
#pragma once

#include <complex>

namespace det {

double sin(double x);
double cos(double x);
double tan(double x);
double asin(double x);
double acos(double x);
double atan(double x);
double atan2(double y, double x);
double exp(double x);
double log(double x);
double log2(double x);
double log10(double x);
double pow(double x, double y);
double tanh(double x);
double hypot(double x, double y);

// std::complex's abs, arg, polar and log, through the functions above.
inline double abs(std::complex<double> z) { return hypot(z.real(), z.imag()); }
inline double arg(std::complex<double> z) { return atan2(z.imag(), z.real()); }
inline std::complex<double> polar(double r, double theta) { return {r * cos(theta), r * sin(theta)}; }
inline std::complex<double> log(std::complex<double> z) { return {log(abs(z)), arg(z)}; }
// n / d as g++'s libgcc divides (__divdc3, Smith's ratio with its scalings: the native bits), written
// out so libc++'s own algorithm (logb/scalbn scaling, WebAssembly) is never used (det_complex.cpp).
std::complex<double> div(std::complex<double> n, std::complex<double> d);

}  // namespace det
