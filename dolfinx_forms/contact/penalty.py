"""The penalty scale of eq 51, the one definition every enforcement uses.

eps_n = eps_t = eps0 h / E_c: h the contact mesh size, E_c = `contact_modulus`, the most
compliant contact's modulus. The penalty uses it with the user's eps0; the augmented
Lagrangian's point-wise regularisation with its own factors (`defaults.TUNING`),
the user's eps0 then only setting the Uzawa step.

Why the contact's modulus and not the mean of the bodies' moduli (the scale the penalty path
used until the package was split): the two agree on every scene of equal moduli (Hertz, the
patch test, two blocks, the grain assemblies, whose softest contact is grain on grain); they
differ where moduli differ or a body touches only rigid obstacles. A soft disc (E 200) between
stiff blocks (E 1e5): the mean gives 66733, the contact 399, and the mean's penalty was 167
times too stiff there (a checkerboard, tests/app/test_scenes.py). A disc between rigid platens
(the Brazilian disc): E_c = 2 E, the harmonic mean with an infinitely stiff partner, as the
contact compliance of Hertz's E* halves against a rigid flat; the demo's default eps0 doubled
with it (0.3 -> 0.6: the same eps_n, the same figures).
"""

import numpy as np


def contact_modulus(scene, laws, obstacles=()):
    """Over the scene's pairs, the smallest harmonic mean 2 / (1/E_i + 1/E_j) of the two
    bodies' moduli (a rigid obstacle: 2 E of its body), i.e. the most compliant contact; the
    mean modulus if there is no contact at all. laws: {body tag: Law}."""
    E = {b.tag: laws[int(b.tag)].modulus for b in scene.bodies}
    tags = [b.tag for b in scene.bodies]
    pairs = [2.0 * E[tags[i]] * E[tags[j]] / (E[tags[i]] + E[tags[j]]) for i, j in scene.pairs]
    for ob in obstacles:
        held = [t for t in tags if ob.bodies is None or t in np.atleast_1d(ob.bodies)]
        pairs += [2.0 * E[t] for t in held]
    return min(pairs) if pairs else float(np.mean(list(E.values())))


def penalty_parameter(eps0, h, modulus):
    """eq 51: eps = eps0 h / E (a compliance: length per stress)."""
    return float(eps0) * float(h) / float(modulus)
