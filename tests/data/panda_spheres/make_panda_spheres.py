"""robots/panda.urdf with its collision capsules replaced by the 59 spheres of VAMP's
panda_spherized.urdf: writes panda_spheres.urdf beside this script."""
# VAMP panda_spherized.urdf spheres (KavrakiLab/vamp resources/panda), per link: (x, y, z, r)
import math, os, re

HERE = os.path.dirname(os.path.abspath(__file__))
S = {
 'panda_link0': [(0,0,0.05,0.08)],
 'panda_link1': [(0,-0.08,0,0.06),(0,-0.03,0,0.06),(0,0,-0.12,0.06),(0,0,-0.17,0.06)],
 'panda_link2': [(0,0,0.03,0.06),(0,0,0.08,0.06),(0,-0.12,0,0.06),(0,-0.17,0,0.06)],
 'panda_link3': [(0,0,-0.1,0.06),(0,0,-0.06,0.05),(0.08,0.06,0,0.055),(0.08,0.02,0,0.055)],
 'panda_link4': [(-0.08,0.095,0,0.06),(0,0,0.02,0.055),(0,0,0.06,0.055),(-0.08,0.06,0,0.055)],
 'panda_link5': [(0,0.055,0,0.06),(0,0.075,0,0.06),(0,0,-0.22,0.06),(0,0.05,-0.18,0.05),
   (0.01,0.08,-0.14,0.025),(0.01,0.085,-0.11,0.025),(0.01,0.09,-0.08,0.025),(0.01,0.095,-0.05,0.025),
   (-0.01,0.08,-0.14,0.025),(-0.01,0.085,-0.11,0.025),(-0.01,0.09,-0.08,0.025),(-0.01,0.095,-0.05,0.025)],
 'panda_link6': [(0,0,0,0.05),(0.08,-0.01,0,0.05),(0.08,0.035,0,0.052)],
 'panda_link7': [(0,0,0.07,0.05),(0.02,0.04,0.08,0.025),(0.04,0.02,0.08,0.025),(0.04,0.06,0.085,0.02),(0.06,0.04,0.085,0.02)],
}
hand = []
for z, r in [(0.01,0.028),(0.03,0.026),(0.05,0.024)]:
    for y in [-0.075,-0.045,-0.015,0.015,0.045,0.075]:
        hand.append((0,y,z,r))
fingers = [(0,0.065,0.0584,[(0,0.015,0.022,0.012),(0,0.008,0.044,0.012)]),
           (0,-0.065,0.0584,[(0,-0.015,0.022,0.012),(0,-0.008,0.044,0.012)])]
c, s = math.cos(-math.pi/4), math.sin(-math.pi/4)
def rot(x,y,z): return (c*x - s*y, s*x + c*y, z)
H = [rot(x,y,z)+(r,) for x,y,z,r in hand]
for ox,oy,oz,sp in fingers:
    for x,y,z,r in sp:
        H.append(rot(x+ox,y+oy,z+oz)+(r,))
S['hand'] = H
print(sum(len(v) for v in S.values()), 'spheres')
src = open(os.path.join(HERE, '../../../robots/panda.urdf')).read()
src = re.sub(r'<!--.*?-->', '', src, flags=re.S)
src = re.sub(r'\s*<(collision|visual)\b.*?</\1>', '', src, flags=re.S)
for link, sp in S.items():
    body = ''.join(f'\n    <collision name="{link}_{i}"><origin xyz="{x:.6g} {y:.6g} {z:.6g}"/><geometry><sphere radius="{r}"/></geometry></collision>' for i,(x,y,z,r) in enumerate(sp))
    src, n = re.subn(rf'<link name="{link}"\s*/>', f'<link name="{link}">{body}\n  </link>', src)
    if n == 0:
        src, n = re.subn(rf'<link name="{link}">\s*</link>', f'<link name="{link}">{body}\n  </link>', src)
    assert n == 1, link
open(os.path.join(HERE, 'panda_spheres.urdf'), 'w').write(src)
