# 20 G01 moves on the paper's G06.5 block (its section 6.2): 21 points at equal steps of arc length.
import math
P=3
X=[[47.7773,71.0202,58.8006],[44.3229,75.6066,54.4778],[37.2164,84.6443,44.5755],[28.7567,101.5653,29.7151],[-1.6963,163.6796,5.8369]]
U=[[47.8066,71.9791,59.0828],[44.3651,76.5494,54.8138],[37.2554,85.5421,45.0342],[28.7081,102.3535,30.3361],[-1.8572,163.9906,6.7762]]
K=[0,0,0,0,0.5046,1,1,1,1]
def N(i,p,u):
    if p==0:
        last=K[-1]
        return 1.0 if (K[i]<=u<K[i+1]) or (u==last and K[i]<u and K[i+1]==last) else 0.0
    a=0.0
    if K[i+p]>K[i]: a+=(u-K[i])/(K[i+p]-K[i])*N(i,p-1,u)
    if K[i+p+1]>K[i+1]: a+=(K[i+p+1]-u)/(K[i+p+1]-K[i+1])*N(i+1,p-1,u)
    return a
def ev(net,u):
    return [sum(N(i,P,u)*net[i][c] for i in range(5)) for c in range(3)]
print("%\n(20 G01 moves on the paper's G06.5 block, Wang et al. 2007 section 6.2, sampled at)")
print("(equal steps of arc length: the 20 moves its Fig. 7 fits into one block)\nG90 G21")
# equal arc length: tabulate s(u) densely, then invert
S=[0.0];UU=[0.0];prev=ev(X,0.0)
for j in range(1,20001):
    uu=j/20000; c=ev(X,uu); S.append(S[-1]+math.dist(c,prev)); UU.append(uu); prev=c
import bisect
for k in range(21):
    target=S[-1]*k/20; j=min(bisect.bisect_left(S,target),20000)
    u=UU[j] if j==0 else UU[j-1]+(UU[j]-UU[j-1])*(target-S[j-1])/max(S[j]-S[j-1],1e-30)
    c=ev(X,u); o=ev(U,u); t=[o[i]-c[i] for i in range(3)]; n=math.sqrt(sum(x*x for x in t)); t=[x/n for x in t]
    w="G01 " if k<2 else ""
    f=" F400" if k==0 else ""
    print("N%d %sX%.4f Y%.4f Z%.4f I%.6f J%.6f K%.6f%s"%(10*(k+1),w,c[0],c[1],c[2],t[0],t[1],t[2],f))
print("M30\n%")
