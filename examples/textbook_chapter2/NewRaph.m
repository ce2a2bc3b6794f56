function q=NewRaph(q0,t)
% q=NewRaph(q0,t)
% Rozwiązanie układu równań metodą Newtona-Raphsona.
% Wejście:
%   q0 - przybliżenie startowe,
%   t - chwila, dla której poszukiwane jest rozwiązanie.
% Wyjście:
%   q - uzyskane rozwiązanie.
%
% Układ równań musi być wpisany w pliku Wiezy.m.
% Macierz Jacobiego układu równań musi być wpisana w pliku Jakobian.m.

q=q0;
F=Wiezy(q,t);
iter=1; % Licznik iteracji
while ( (norm(F)>1e-10) & (iter < 25) )
    F=Wiezy(q,t);
    Fq=Jakobian(q);
    q=q-Fq\F; % Fq\F jest równoważne inv(Fq)*F, ale mniej kosztowne numerycznie
    iter=iter+1;
end
if iter >= 25
    disp('BŁĄD: Po 25 iteracjach Newtona-Raphsona nie uzyskano zbieżności ');
    q=q0;
end
