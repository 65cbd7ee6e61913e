"""A tiny CMU-style ASF skeleton (root, lfemur, ltibia, thorax; limits, a 2-DOF bone) and a 3-frame AMC
take on it: seeds for the reader fuzz tests and ``benchmarks/fuzz.py``, and a quick ASF/AMC example."""

TINY_ASF = """\
:version 1.10
:name fuzz
:units
  mass 1.0
  length 0.45
  angle deg
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name lfemur
     direction 0 -1 0
     length 7
     axis 0 0 20 XYZ
    dof rx ry rz
    limits (-160 20)
           (-70 70)
           (-60 70)
  end
  begin
     id 2
     name ltibia
     direction 0 -1 0
     length 7.5
     axis 0 0 20 XYZ
    dof rx
    limits (-10 170)
  end
  begin
     id 3
     name thorax
     direction 0 1 0
     length 3
     axis 0 0 0 ZYX
    dof rz rx
    limits (-inf inf) (-20 20)
  end
:hierarchy
  begin
    root lfemur thorax
    lfemur ltibia
  end
"""

TINY_AMC = """\
:FULLY-SPECIFIED
:DEGREES
1
root 1 2 3 0 0 0
lfemur 10 -5 3
ltibia 40
thorax 5 2
2
root 1.5 2 3.5 1 2 3
lfemur 12 -4 2
ltibia 45
thorax 6 1
3
root 2 2 4 2 4 6
lfemur 14 -3 1
ltibia 50
thorax 7 0
"""
