"""The loading protocol of the paper (section 2): compress by dL, then shear by dW.

One driver (ddg.protocol.driver) runs it for every model (rod, plate, ribbon, and the FEM shell
in fem_reference) with any stepper (static continuation or implicit Euler,
ddg.protocol.steppers); threshold location and branch tracing are steps after the path
(ddg.protocol.after); the result and its summary.json live in ddg.protocol.results.
"""
