"""What a run yields and what is read off its rows once solved: the Trajectory and the files a
run writes (results), spatial points and angular velocities (spatial), design sensitivities
q_p (sensitivity), the rows removed as redundant checked along the motion (redundant), and a
pair's coordinate past its range ending the motion (ranges).

Imports the loads (a Trajectory carries Forces) and the runtime's protocol, never the solve.
NumPy only.
"""
