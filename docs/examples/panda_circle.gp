# The figure of docs/controller.md: tracking error and motor effort of
# docs/examples/panda_circle.cpp over time, from the CSV it writes.
#
#   build/test/cli/example_panda_circle --csv /tmp/panda_circle.csv
#   gnuplot -e "csv='/tmp/panda_circle.csv'; out='docs/examples/panda_circle.png'" docs/examples/panda_circle.gp
if (!exists("csv")) csv = "/tmp/panda_circle.csv"
if (!exists("out")) out = "panda_circle.png"
set encoding utf8
set terminal pngcairo size 1000,700 font "DejaVu Sans,11"
set output out
set datafile separator ","
set key autotitle columnhead
set multiplot layout 2,1
set grid
set ylabel "tracking error"
set logscale y
set format y "10^{%L}"
set yrange [1e-7:*]
plot csv using 1:2 with lines lw 2 title "position [m]", \
     csv using 1:3 with lines lw 2 title "tool axis [rad]"
unset logscale y
set format y "%g"
set yrange [*:*]
set xlabel "t [s]"
set ylabel "‖τ_{control}‖² [N²m²]"
plot csv using 1:4 with lines lw 2 lc rgb "#b03030" title "motor effort"
unset multiplot
