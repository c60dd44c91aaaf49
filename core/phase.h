// Phase functions: the angular distribution of singly scattered light, per
// steradian, for the cosine mu of the scattering angle. Each integrates to 1
// over the sphere. The GLSL runtime has its own copies
// (shaders_runtime/functions.glsl).
#pragma once

namespace skybake {

// 1 / (4 pi).
double IsotropicPhase();

// 3 / (16 pi) (1 + mu^2).
double RayleighPhase(double mu);

// (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^(3/2)), asymmetry |g| < 1.
double HenyeyGreensteinPhase(double g, double mu);

// Cornette and Shanks (1992):
// 3 / (8 pi) (1 - g^2) / (2 + g^2) (1 + mu^2) / (1 + g^2 - 2 g mu)^(3/2).
double CornetteShanksPhase(double g, double mu);

}  // namespace skybake
