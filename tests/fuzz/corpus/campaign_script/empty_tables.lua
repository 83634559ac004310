return { needs = {}, parameters = {}, run = function(p) end }
