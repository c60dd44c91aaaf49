// skybake GLSL runtime: phase functions, per steradian, of the cosine nu of the
// scattering angle; each integrates to 1 over the sphere. The one definition
// used by the sky runtime (sky.glsl), the dome model
// (hoffman_preetham.glsl) and, compiled as C++ (primitives.h), by the
// bake in double and in float. Literals are written Number(...) for the float
// instantiation (see primitives.glsl).

Number IsotropicPhaseFunction() {
  return Number(1.0) / (Number(4.0) * PI);
}

// 3 / (16 pi) (1 + nu^2).
Number RayleighPhaseFunction(Number nu) {
  Number k = Number(3.0) / (Number(16.0) * PI);
  return k * (Number(1.0) + nu * nu);
}

// (1 - g^2) / (4 pi (1 + g^2 - 2 g nu)^(3/2)), asymmetry |g| < 1.
Number HenyeyGreensteinPhaseFunction(Number g, Number nu) {
  Number denom = Number(1.0) + g * g - Number(2.0) * g * nu;
  return (Number(1.0) - g * g) / (Number(4.0) * PI * denom * sqrt(denom));
}

// Cornette and Shanks (1992):
// 3 / (8 pi) (1 - g^2) / (2 + g^2) (1 + nu^2) / (1 + g^2 - 2 g nu)^(3/2).
Number CornetteShanksPhaseFunction(Number g, Number nu) {
  Number denom = Number(1.0) + g * g - Number(2.0) * g * nu;
  Number k = Number(3.0) / (Number(8.0) * PI) * (Number(1.0) - g * g) / (Number(2.0) + g * g);
  return k * (Number(1.0) + nu * nu) / (denom * sqrt(denom));
}
