"""The fitting engine (docs/architecture.md#identification): parameters, the problem (a model's residuals against
measured traces, and their Jacobian), the optimiser, the uncertainty at the optimum, and the residual statistics
(the noise estimated from the data, a fit's adequacy).

It knows residuals and Jacobians, never what they measure: a trace carries its measurement, an object whose
``residuals`` and ``per_trace`` the problem calls (thermofriction/measurements/ implements them), as lmfit's
``Minimizer`` knows nothing of its ``Model``. Nothing here imports ``measurements`` or ``identification``; both
import it."""
