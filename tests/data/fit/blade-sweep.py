# A blade-like 5-axis sweep: the cutter runs along a twisted, cambered curve at 0.1 mm
# steps while the tool axis leans and swings smoothly (as a flank or point-milling pass
# over an impeller blade). Points to 4 decimals, axes to 6, like a post-processor writes.
import math, sys
n=int(sys.argv[1]) if len(sys.argv)>1 else 3000
step=0.1
print("%%\n(blade-like 5-axis sweep, %d moves of %.2f mm)\nG90 G21 G94"%(n,step))
# parametric curve, resampled at equal arc length
def c(t):
    return (40*math.cos(t)+3*math.cos(3*t), 40*math.sin(t)+2*math.sin(2*t), 10+8*t+1.5*math.sin(5*t))
def axis(t):
    lean=math.radians(15+10*math.sin(2*t)); sw=t+math.radians(30)*math.sin(t)
    v=(math.sin(lean)*math.cos(sw), math.sin(lean)*math.sin(sw), math.cos(lean)); return v
T=[0.0];S=[0.0];prev=c(0.0);t=0.0;dt=1e-4
while S[-1]<n*step+1:
    t+=dt; p=c(t); S.append(S[-1]+math.dist(p,prev)); T.append(t); prev=p
import bisect
for k in range(n+1):
    s=k*step; j=bisect.bisect_left(S,s); 
    tt=T[j] if j==0 else T[j-1]+(T[j]-T[j-1])*(s-S[j-1])/(S[j]-S[j-1])
    p=c(tt); a=axis(tt)
    g="G01 " if k<2 else ""
    f=" F3000" if k==0 else ""
    print("N%d %sX%.4f Y%.4f Z%.4f I%.6f J%.6f K%.6f%s"%(10*(k+1),g,p[0],p[1],p[2],a[0],a[1],a[2],f))
print("M30\n%")
