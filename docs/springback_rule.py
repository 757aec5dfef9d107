# Released curvature of an elastic-perfectly-plastic rectangular section bent to k = 2 and 5
# times its yield curvature, with the solid-shell thickness rules of 3-12 points (the same
# rules as element::solid_shell::thickness_rule), under curvature and under moment control.
# Units: half-thickness 1, sigma_y = 1, E = 1 (so kappa_e = 1). python3 docs/springback_rule.py
import math
def leg(n,z):
    p0,p1=1.0,z
    for k in range(2,n+1): p0,p1=p1,((2*k-1)*z*p1-(k-1)*p0)/k
    dp=n*(z*p1-p0)/(z*z-1); return p1,dp
def gauss(n):
    xs=[];ws=[]
    for i in range(n):
        z=math.cos(math.pi*(i+0.75)/(n+0.5))
        for _ in range(100):
            p,dp=leg(n,z); z-=p/dp
        p,dp=leg(n,z); xs.append(z); ws.append(2/((1-z*z)*dp*dp))
    return xs,ws
def rule(n):
    if n==3: return [-1,0,1.],[1/3,4/3,1/3]
    if n<5 or n%2==0: return gauss(n)
    m=(n-1)//2; h=1/m; half=[0.0]*(m+1)
    s= m if m%2==0 else m-3
    for i in range(0,s,2):
        half[i]+=h/3; half[i+1]+=4*h/3; half[i+2]+=h/3
    if s<m:
        for k,c in enumerate([1,3,3,1]): half[s+k]+=3*h/8*c
    x=[-1+i*h for i in range(n)]; w=[0.0]*n
    for i,wi in enumerate(half): w[m+i]+=wi; w[m-i]+=wi
    return x,w
def Mh(n,k):
    x,w=rule(n); return sum(wi*max(-1,min(1,k*xi))*xi for xi,wi in zip(x,w))
Me=2/3
for n in range(3,13):
    out=[]
    for k in [2,5]:
        Mex=Me*1.5*(1-(1/k**2)/3); kres=k-Mex/Me
        krc=k-Mh(n,k)/Me
        lo,hi=0.0,100.0
        if Mh(n,hi)<Mex: kk=float('inf')
        else:
            for _ in range(200):
                mid=(lo+hi)/2
                if Mh(n,mid)<Mex: lo=mid
                else: hi=mid
            kk=hi
        krm=kk-Mex/Me
        out.append(f"k={k}: curv {100*(krc/kres-1):+.2f}%  mom kappa {kk:.3f} kres {100*(krm/kres-1):+.1f}%")
    print(n,"  ".join(out))
