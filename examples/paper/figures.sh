#!/bin/sh
# Regenerates the paper's §6 figures as SVG from a2ml's own plans:
#   examples/paper/figures.sh [OUT_DIR]      (default: target/paper-figures)
# with the `a2ml` binary on PATH or in $A2ML. Each picture is planned
# afresh from the task files; docs/paper.md says which figure is which.
# `a2ml plot` exits 3 when a goal is missed and still writes the picture
# (fig. 7(a) and (c) are such plans), so only a failure to write stops this.
set -u
here=$(cd "$(dirname "$0")" && pwd)
out=${1:-target/paper-figures}
a2ml=${A2ML:-a2ml}
mkdir -p "$out"
status=0

# draw TASK KIND NAME: the picture of one kind, OUT/NAME.svg
draw() {
  "$a2ml" plot "$1" --kind "$2" -o "$out/$3.svg"
  code=$?
  if [ "$code" -ne 0 ] && [ "$code" -ne 3 ]; then
    echo "figures.sh: $3 failed (exit $code)" >&2
    status=1
  fi
}

# §6.2, fig. 7 and 8: forward bar by QP (a) and by RRT (b), lateral bar by QP (c):
# the wrist path (fig. 8(a)) and the featured variables against their references,
# the swivel profile among them (fig. 8(b)).
for case in "$here/forward_bar_qp.a2ml:fig7a" "$here/../type_iv_forward_bar.a2ml:fig7b" \
            "$here/../type_iv_lateral_bar.a2ml:fig7c"; do
  task=${case%:*} name=${case##*:}
  draw "$task" wrist "${name}_wrist"
  draw "$task" featured "${name}_featured"
done

# §6.3, fig. 9: the two type VII variants, same start, same goal.
draw "$here/type_vii_about_r.a2ml" joints fig9a_joints
draw "$here/type_vii_about_minus_z.a2ml" joints fig9b_joints
draw "$here/type_vii_about_r.a2ml" featured fig9a_featured
draw "$here/type_vii_about_minus_z.a2ml" featured fig9b_featured

# §6.3, fig. 10(a) and 11: the column run (MS1 by the constrained RRT), and each capsule's
# distance to the column; both variants of fig. 9, which end in one configuration.
draw "$here/type_vii_column.a2ml" wrist fig10a_wrist
draw "$here/type_vii_column.a2ml" joints fig10a_joints
draw "$here/type_vii_column.a2ml" distances fig11_distances
draw "$here/type_vii_column_about_minus_z.a2ml" wrist fig10a_minus_z_wrist
draw "$here/type_vii_column_about_minus_z.a2ml" distances fig11_minus_z_distances

# §6.3, fig. 10(b): GPM on the straight wrist path, through the column and past joint 6's limit.
draw "$here/column_gpm_straight.a2ml" joints fig10b_joints
draw "$here/column_gpm_straight.a2ml" distances fig10b_distances

# §6.3, fig. 12: GPM on the three semi-elliptic wrist paths: the paths (a) and the joints,
# joints 4 (RElbj) and 6 (RWrj1) among them against their shaded limits (b, c).
for plane in minus30 0 plus30; do
  draw "$here/column_gpm_arc_$plane.a2ml" wrist "fig12a_wrist_$plane"
  draw "$here/column_gpm_arc_$plane.a2ml" joints "fig12_joints_$plane"
done

# §6.4, fig. 13(d) and (e): the push-box task's joints on Centauro and on COMAN.
draw "$here/../push_box_aside_centauro.a2ml" joints fig13d_joints
draw "$here/../push_box_aside_coman.a2ml" joints fig13e_joints

exit $status
