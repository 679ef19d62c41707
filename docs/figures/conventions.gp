# The figure of docs/conventions.md: frames and signs, drawn on the report's
# 1-DOF arm seen from above (the joint axis z points out of the page).
#
#   cd docs/figures && gnuplot conventions.gp          # writes conventions.png
#   gnuplot -e "out='/tmp/c.png'" docs/figures/conventions.gp
#
# Left: the arm at q = 35°, its frames, the signs of q, τ, μ, a tip wrench and a
# constraint direction. Right: the layout of the numbers.
if (!exists("out")) out = "conventions.png"
set encoding utf8
set terminal pngcairo size 1300,720 font "DejaVu Sans,12"
set output out

set parametric
set trange [0:1]
unset border; unset tics; unset key
set size ratio -1
set xrange [-2.2:14.6]
set yrange [-2.6:6.6]
set margins 1, 1, 1, 1

deg = pi / 180
q = 35 * deg
L = 5.0                           # link length on the drawing (the report's 1 m)
tx = L * cos(q); ty = L * sin(q)  # tip
ax = 1.6                          # axis arrow length
black = "#000000"; blue = "#0050b0"; green = "#208020"; red = "#c00000"; grey = "#808080"; purple = "#7030a0"

# --- the link
set arrow 1 from 0,0 to tx,ty nohead linewidth 14 linecolor rgb "#d8d8d8" back
set object 1 circle at 0,0 size 0.22 fillstyle solid 1.0 fillcolor rgb "white" front
set object 2 circle at 0,0 size 0.22 fillstyle empty border rgb black linewidth 2 front
set object 3 circle at 0,0 size 0.05 fillstyle solid 1.0 fillcolor rgb black front
set label 1 "joint 1, axis z out of the page ⊙\nlink frame \\{1\\} = joint frame after the motion" at 0.15,-0.75 left textcolor rgb black

# --- world frame {0} at the base (black)
set arrow 2 from 0,0 to ax+0.6,0 head filled size 0.25,20 linewidth 2.5 linecolor rgb black
set arrow 3 from 0,0 to 0,ax+0.6 head filled size 0.25,20 linewidth 2.5 linecolor rgb black
set label 2 "x₀" at ax+0.75,0 left textcolor rgb black
set label 3 "y₀" at 0.2,ax+0.5 left textcolor rgb black
set label 4 "world \\{0\\}, z₀ up:\ngravity (0, 0, −9.81) points into the page ⊗" at -2.1,-1.75 left textcolor rgb black

# --- link frame {1} at the joint (blue)
set arrow 4 from 0,0 to ax*cos(q),ax*sin(q) head filled size 0.25,20 linewidth 2.5 linecolor rgb blue
set arrow 5 from 0,0 to -ax*sin(q),ax*cos(q) head filled size 0.25,20 linewidth 2.5 linecolor rgb blue
set label 5 "x₁" at ax*cos(q)+0.05,ax*sin(q)-0.3 left textcolor rgb blue
set label 6 "y₁" at -ax*sin(q)-0.45,ax*cos(q)+0.1 left textcolor rgb blue

# --- q > 0: counter-clockwise about z (arc drawn below, arrowhead here)
r_q = 1.05
set arrow 6 from r_q*cos(q-4*deg),r_q*sin(q-4*deg) to r_q*cos(q),r_q*sin(q) head filled size 0.2,25 linecolor rgb black
set label 7 "q > 0" at 1.15,0.32 left textcolor rgb black

# --- τ > 0 (green) and the friction reaction −μ (red) at the joint
r_t = 2.8
a1 = 60 * deg; a2 = 140 * deg
set arrow 7 from r_t*cos(a2-3*deg),r_t*sin(a2-3*deg) to r_t*cos(a2),r_t*sin(a2) head filled size 0.25,25 linewidth 2.5 linecolor rgb green
set label 8 "τ > 0 accelerates q positively" at -2.1,3.6 left textcolor rgb green
r_m = 3.4
b1 = 150 * deg; b2 = 95 * deg
set arrow 8 from r_m*cos(b2+3*deg),r_m*sin(b2+3*deg) to r_m*cos(b2),r_m*sin(b2) head filled size 0.25,25 linewidth 2.5 linecolor rgb red
set label 9 "the joint feels −μ: μ > 0 opposes positive motion\n(τ_{eff} = τ − μ; |μ| ≤ f, the breakaway torque)" at -2.1,4.55 left textcolor rgb red

# --- tip frame: local axes (blue) and world = aligned axes (black, dashed), same origin
set arrow 9  from tx,ty to tx+ax*cos(q),ty+ax*sin(q) head filled size 0.25,20 linewidth 2.5 linecolor rgb blue
set arrow 10 from tx,ty to tx-ax*sin(q),ty+ax*cos(q) head filled size 0.25,20 linewidth 2.5 linecolor rgb blue
set arrow 11 from tx,ty to tx+ax,ty head filled size 0.25,20 linewidth 2 dashtype 2 linecolor rgb black
set arrow 12 from tx,ty to tx,ty+ax head filled size 0.25,20 linewidth 2 dashtype 2 linecolor rgb black
set label 10 "local" at tx+ax*cos(q)+0.1,ty+ax*sin(q)+0.15 left textcolor rgb blue
set label 11 "world = aligned" at tx+ax+0.1,ty-0.05 left textcolor rgb black
set object 4 circle at tx,ty size 0.1 fillstyle solid 1.0 fillcolor rgb black front
set label 12 "tip frame: a wrench acts at its origin;\nan acceleration is that of its origin" at tx+0.5,ty+2.75 left textcolor rgb black

# --- a wrench at the tip: force −y₀ (the report's scenarios: −5 N, −11 N)
set arrow 13 from tx,ty to tx,ty-2.0 head filled size 0.3,20 linewidth 3.5 linecolor rgb purple
set label 13 "wrench on tip, world axes:\nforce (0, −F, 0), torque (0, 0, 0)" at tx+0.2,ty-2.2 left textcolor rgb purple

# --- a constraint direction on the tip: local y₁, linear part (orange, behind the axes)
set arrow 14 from tx,ty to tx-2.6*sin(q),ty+2.6*cos(q) head filled size 0.3,20 linewidth 8 linecolor rgb "#70f0a040" back
set label 14 "constraint column [l; r] = [0 1 0; 0 0 0], local (orange):\nlᵀ p̈ = b; the constraint exerts +A ν on the frame" at tx-0.4,ty-3.25 left textcolor rgb "#e07000"

# --- the right-hand panel: how the numbers are laid out
set object 10 rectangle from 9.3,-2.45 to 14.5,6.45 fillstyle empty border rgb grey linewidth 1 back
set label 20 "{/:Bold numbers}" at 9.5,6.0 left
set label 21 "spatial vectors, linear part first:\n  motion  [v; ω]   (Plücker)\n  force    [f; n]\n  v× = [ω×  v×; 0  ω×],  v×* = −(v×)ᵀ" at 9.5,5.35 left
set label 22 "acceleration (user side): classical,\ntrue, of the frame origin: [p̈; ω̇],\ngravity not included" at 9.5,3.3 left
set label 23 "expressed in: only the axes change\n  local   the frame's own axes\n  world   world axes (= aligned)" at 9.5,1.65 left
set label 24 "signs: q, q̇, q̈, τ > 0 about +axis;\nμ > 0 opposes positive motion" at 9.5,0.2 left
set label 25 "constraint Aᵀ Ẍ = b: columns of A\nare unit forces [l; r]; constraint\nwrench + A ν; τ_c = Σ Jᵀ A ν;\nτ_{control} = τ + τ_c (to the motors)" at 9.5,-1.2 left

plot \
  r_q*cos(q*t), r_q*sin(q*t) with lines linewidth 1.5 linecolor rgb black, \
  r_t*cos(a1+(a2-a1)*t), r_t*sin(a1+(a2-a1)*t) with lines linewidth 2.5 linecolor rgb green, \
  r_m*cos(b1+(b2-b1)*t), r_m*sin(b1+(b2-b1)*t) with lines linewidth 2.5 linecolor rgb red
