"""Runs driven by input drivers (symkin.solve with inputs=): the checked inputs table and each
point solved from the last solution (inputs), the loop over the rows with its failures and
interrupts (input_runs), and the rows that may have jumped to another assembly (branch).

Built on the solving room and the outputs; the driver reaches it, it never reaches the driver.
"""
