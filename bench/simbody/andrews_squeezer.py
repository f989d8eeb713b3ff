#!/usr/bin/env python3
"""Writes verification/cases/andrews_squeezer.yaml: Andrews' squeezer (Hairer and Wanner, Solving ODEs II,
section VII.7; the Bari test set's "andrews") as railcrash bodies and pin joints.

The centres of mass are placed at the test set's consistent angles by chaining the joints
from the fixed points O, A, B; the loop must close at E (checked). Joint points are offsets
from each body's centre of mass along its axes (also used by bench/simbody/mechanisms.cpp).
"""
from math import sin, cos, hypot

HEADER = '''railcrash: 1
name: Andrews' squeezer mechanism (seven-body test problem)
description: >
  The seven-body mechanism of Schiehlen's benchmark as given by Hairer and Wanner, Solving
  Ordinary Differential Equations II, section VII.7, and the Bari test set for IVP solvers
  ("andrews"): masses, inertias, geometry, drive moment 0.033 N m on the crank, spring
  4530 N/m (free length 0.07785 m) from the lever to the fixed point C, no gravity, started
  at rest from the test set's consistent angles (beta -0.0617..., gamma 0.4553..., phi
  0.2227..., delta 0.4874..., Omega -0.2227..., epsilon 1.2305...). Body positions are
  the centres of mass at those angles (bench/simbody/andrews_squeezer.py writes this file);
  each joint point is an offset from its body's centre of mass along the body's axes. Used
  by bench/simbody/compare.py against the same mechanism in Simbody and checked against the
  test set's solution at t = 0.03 s by verification/verify.cpp.
units: SI
gravity: [0, 0]
'''
FOOTER = '''simulation:
  t_end: 0.03
  integrator: ida
  rtol: 1.0e-6
  atol: 1.0e-9
  output_interval: 1.0e-3
'''

m=[.04325,.00365,.02373,.00706,.07050,.00706,.05498]
I=[2.194e-6,4.410e-7,5.255e-6,5.667e-7,1.169e-5,5.667e-7,1.912e-5]
xa,ya,xb,yb,xc,yc=-.06934,-.00227,-.03635,.03273,.014,.072
d,da,e,ea,rr,ra=28e-3,115e-4,2e-2,1421e-5,7e-3,92e-5
ss,sa,sb,sc,sd=35e-3,1874e-5,1043e-5,18e-3,2e-2
ta,tb,u,ua,ub=2308e-5,916e-5,4e-2,1228e-5,449e-5
zf,zt,fa,mom,c0,lo=2e-2,4e-2,1421e-5,0.033,4530.,0.07785
be,th,ga,ph,de,om,ep=(-0.0617138900142764496358948458001,0.,0.455279819163070380255912382449,
 0.222668390165885884674473185609,0.487364979543842550225598953530,-0.222668390165885884674473185609,1.23054744454982119249735015568)
ang=[be,be+th,ga,ph+de,de,om+ep,ep]
# local points relative to each body's centre of mass
pts={
 'O1':(0,(-ra,0)),'P1':(0,(rr-ra,0)),'P2':(1,(da,0)),'E2':(1,(-(d-da),0)),
 'E3':(2,(-sb,-(ss-sa))),'D3':(2,(sd-sb,sa-sc)),'B3':(2,(-sb,sa)),
 'E4':(3,(0,-ea)),'F4':(3,(0,e-ea)),'A5':(4,(-ta,-tb)),'F5':(4,(zt-ta,-tb)),
 'E6':(5,(fa,0)),'G6':(5,(-(zf-fa),0)),'A7':(6,(ub,ua)),'G7':(6,(ub,-(u-ua)))}
# centres of mass, chained from the fixed points
def rot(a,p): return (cos(a)*p[0]-sin(a)*p[1], sin(a)*p[0]+cos(a)*p[1])
com=[None]*7
def place(body, point_name, world):
    b,p=pts[point_name]; r=rot(ang[b],p); com[b]=(world[0]-r[0],world[1]-r[1])
def world(name):
    b,p=pts[name]; r=rot(ang[b],p); return (com[b][0]+r[0],com[b][1]+r[1])
place(0,'O1',(0,0)); place(1,'P2',world('P1')); place(2,'B3',(xb,yb)); place(4,'A5',(xa,ya))
place(3,'F4',world('F5')); place(6,'A7',(xa,ya)); place(5,'G6',world('G7'))
E=world('E2')
for n in ['E3','E4','E6']:  # the loop closes at E at the test set's angles
    w=world(n); assert hypot(w[0]-E[0],w[1]-E[1]) < 1e-15, n
names=['crank','rod','lever','link4','rocker5','link6','rocker7']
out=[]
out.append('bodies:')
for k in range(7):
    out.append(f"  - {{name: {names[k]}, mass: {m[k]}, inertia: {I[k]}, position: [{com[k][0]!r}, {com[k][1]!r}], angle: {ang[k]!r}}}")
def joint(name,a,b,ground=None):
    def pt(x):
        if x[0]=='ground': return f"{{body: ground, at: [{x[1][0]!r}, {x[1][1]!r}]}}"
        bb,p=pts[x]; return f"{{body: {names[bb]}, at: [{p[0]!r}, {p[1]!r}]}}"
    return f"  - {{name: {name}, type: pin_joint, points: [{pt(a)}, {pt(b)}]}}"
out.append('elements:')
out.append(joint('pivot_O',('ground',(0.0,0.0)),'O1'))
out.append(joint('pin_P','P1','P2'))
out.append(joint('pivot_B',('ground',(xb,yb)),'B3'))
out.append(joint('pivot_A5',('ground',(xa,ya)),'A5'))
out.append(joint('pivot_A7',('ground',(xa,ya)),'A7'))
out.append(joint('pin_F','F5','F4'))
out.append(joint('pin_G','G7','G6'))
out.append(joint('pin_E3','E2','E3'))
out.append(joint('pin_E4','E2','E4'))
out.append(joint('pin_E6','E2','E6'))
b,p=pts['D3']
out.append(f"  - {{name: spring, type: linear_spring, stiffness: {c0}, free_length: {lo}, points: [{{body: lever, at: [{p[0]!r}, {p[1]!r}]}}, {{body: ground, at: [{xc}, {yc}]}}]}}")
out.append('loads:')
out.append(f"  - {{type: moment, body: crank, value: {mom}}}")
import os
with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'verification', 'cases', 'andrews_squeezer.yaml'), 'w') as f:
    f.write(HEADER + '\n'.join(out) + '\n' + FOOTER)

