"""symkin scan: every assembly at t0 and given inputs by deflated multi-start Newton
(assemblies), and what the motion on each branch meets over the driver range (scan).

The top room of the runtime: it runs the driver (symkin.solve), so nothing in the runtime
imports it.
"""
