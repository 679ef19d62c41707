# The figure of docs/mujoco.md, "Soft friction against exact friction": MuJoCo's drift from rest on the DOFs
# zwang holds still, per solver setting, from the CSV `zwang compare-mujoco --csv DIR` writes (zwang's is 0).
#
#   zwang compare-mujoco models/one_dof_arm.xml --state docs/mujoco/one_dof_arm_5N.json --csv /tmp/arm
#   gnuplot -e "csv='/tmp/arm/compare_drift.csv'; out='docs/mujoco/one_dof_arm_drift.png'; posture=0" docs/mujoco/compare_drift.gp
if (!exists("csv")) csv = "compare_drift.csv"
if (!exists("out")) out = "compare_drift.png"
if (!exists("posture")) posture = 0
if (!exists("title")) title = "MuJoCo's drift from rest where zwang sticks (zwang: 0)"
set encoding utf8
set terminal pngcairo size 900,500 font "DejaVu Sans,11"
set output out
set datafile separator ","
set grid
set title title
set xlabel "t [s]"
set ylabel "largest |q(t) − q(0)| on the held DOFs [rad or m]"
set logscale y
set format y "10^{%L}"
set key top left
plot csv using ($1 == posture && $2 > 0 ? $2 : 1/0):3 with lines lw 2 title "default", \
     csv using ($1 == posture && $2 > 0 ? $2 : 1/0):4 with lines lw 2 title "noslip", \
     csv using ($1 == posture && $2 > 0 ? $2 : 1/0):5 with lines lw 2 title "tight"
