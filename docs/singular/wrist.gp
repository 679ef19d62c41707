# The figure of docs/solver.md, "Singular tasks". Regenerate from the repository root:
#   ZWANG_SINGULAR_CSV=docs/singular/wrist.csv build/test/zwang_tests "[sweep]"
#   (cd docs/singular && gnuplot wrist.gp)
set encoding utf8
set terminal pngcairo size 900,700 font "DejaVu Sans,11" noenhanced
set output "wrist.png"
set multiplot layout 2,1 title "6-joint arm through its wrist singularity (q5 = 0), tool held still (6 world rows, b = 0) while moving"
set grid
set key top right box
set xrange [-0.004:0.004]
set format x "%.0e"
set logscale y
set ylabel "|ν| [N, N·m]"
plot "wrist.csv" using 1:3 with lines linewidth 2 dashtype 2 linecolor rgb "#c00000" title "pseudo-inverse, no ramp (threshold 2e-11)", \
     "wrist.csv" using 1:2 with lines linewidth 2 linecolor rgb "#0060c0" title "default (singular_threshold 1e-6)"
set ylabel "‖Aᵀ Ẍ − b‖ [m/s², rad/s²]"
set xlabel "q5 [rad]"
set yrange [1e-16:10]
plot "wrist.csv" using 1:5 with lines linewidth 2 dashtype 2 linecolor rgb "#c00000" title "pseudo-inverse, no ramp", \
     "wrist.csv" using 1:4 with lines linewidth 2 linecolor rgb "#0060c0" title "default: residual reported (status.residual)"
unset multiplot
