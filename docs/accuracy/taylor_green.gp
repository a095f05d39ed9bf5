# taylor_green.gp: the chart of sph2d bench accuracy's taylor green case, what accuracy costs in
# time: error against wall seconds per simulated second, log-log, one series per solver (filled
# marks: the solver's default CFL-type number, open: twice it), each point labelled with its
# particle count, the Pareto front drawn. Its data: taylor_green.dat beside it.
#   gnuplot taylor_green.gp                 draws taylor_green.svg and taylor_green.png beside this file
#   gnuplot -c taylor_green.gp A.svg B.png   draws A.svg and B.png
me = "taylor_green.gp"
n = strlen(ARG0) - strlen(me)
dir = (n > 0 && ARG0[n+1:] eq me) ? ARG0[1:n] : ""
data = dir . "taylor_green.dat"
svg = ARGC >= 1 ? ARG1 : dir . "taylor_green.svg"
png = ARGC >= 2 ? ARG2 : dir . "taylor_green.png"

set encoding utf8
set logscale xy
set xrange [0.0233885:19.8166]
set yrange [0.0184282:0.373835]
set xtics ("0.05" 0.05, "0.1" 0.1, "0.2" 0.2, "0.5" 0.5, "1" 1, "2" 2, "5" 5, "10" 10)
set ytics ("0.02" 0.02, "0.05" 0.05, "0.1" 0.1, "0.2" 0.2)
set lmargin at screen 0.115; set rmargin at screen 0.8
set bmargin at screen 0.095; set tmargin at screen 0.88
set xlabel "cost: wall seconds per simulated second  (s/s)"
set ylabel "error: RMS of |u|_{max}/U against exp(-8π^2 t/Re)\n(share of U)"
set title "taylor green: error against cost\n{/*0.8 lower left is better; the grey line joins the Pareto front: the runs no other run beats in both}"
set grid xtics ytics lc rgb "#dddddd" lw 1
set key outside right top vertical Left reverse noenhanced spacing 1.15 font ",10"

set terminal svg size 960,600 fixed enhanced font "DejaVu Sans,12" background rgb "white"
set output svg
plot \
  data index 5 using 1:2 with lines lw 8 lc rgb "#a0909090" title "Pareto front", \
  data index 5 using 1:2 with points pt 6 ps 2.6 lw 1.5 lc rgb "#606060" notitle, \
  data index 0 using 1:($4 == 1 ? $2 : NaN) with points pt 7 ps 1.4 lc rgb "#E69F00" title "muller2003", \
  data index 0 using 1:($4 != 1 ? $2 : NaN) with points pt 6 ps 1.4 lw 2 lc rgb "#E69F00" notitle, \
  data index 0 using 6:7:3 with labels left font ",9" tc rgb "#E69F00" notitle, \
  data index 1 using 1:($4 == 1 ? $2 : NaN) with points pt 5 ps 1.4 lc rgb "#0072B2" title "wcsph", \
  data index 1 using 1:($4 != 1 ? $2 : NaN) with points pt 4 ps 1.4 lw 2 lc rgb "#0072B2" notitle, \
  data index 1 using 6:7:3 with labels left font ",9" tc rgb "#0072B2" notitle, \
  data index 2 using 1:($4 == 1 ? $2 : NaN) with points pt 9 ps 1.4 lc rgb "#009E73" title "dfsph", \
  data index 2 using 1:($4 != 1 ? $2 : NaN) with points pt 8 ps 1.4 lw 2 lc rgb "#009E73" notitle, \
  data index 2 using 6:7:3 with labels left font ",9" tc rgb "#009E73" notitle, \
  data index 3 using 1:($4 == 1 ? $2 : NaN) with points pt 13 ps 1.4 lc rgb "#CC79A7" title "pbf", \
  data index 3 using 1:($4 != 1 ? $2 : NaN) with points pt 12 ps 1.4 lw 2 lc rgb "#CC79A7" notitle, \
  data index 3 using 6:7:3 with labels left font ",9" tc rgb "#CC79A7" notitle, \
  data index 4 using 1:($4 == 1 ? $2 : NaN) with points pt 15 ps 1.4 lc rgb "#D55E00" title "game", \
  data index 4 using 1:($4 != 1 ? $2 : NaN) with points pt 14 ps 1.4 lw 2 lc rgb "#D55E00" notitle, \
  data index 4 using 6:7:3 with labels left font ",9" tc rgb "#D55E00" notitle, \
  keyentry with points pt 7 ps 1.4 lc rgb "#404040" title "CFL ×1", \
  keyentry with points pt 6 ps 1.4 lw 2 lc rgb "#404040" title "CFL ×2"
unset output

if (strstrt(" " . GPVAL_TERMINALS . " ", " pngcairo ") > 0) {
  set terminal pngcairo size 960,600 enhanced font "DejaVu Sans,11" background rgb "white"
} else {
  set terminal png size 960,600 enhanced font "DejaVuSans,10" background rgb "white"
}
set output png
replot
unset output
